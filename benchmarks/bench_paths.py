"""The fast right-hand side against the previous dense path, whole trajectories, in one process.

Usage: python benchmarks/bench_paths.py [--cases 100:60,150:45,150:80] [--orders 16,24,32]
                                     [--t-end 10] [--rtol 1e-6] [--repeats 2] [--out FILE.json]
                                     [--baseline REV]

Both paths integrate the same start (``shapes.initial_shape``, perturbation 1e-3,
seed 0) with radau5 and the same exact Jacobian; only the RHS differs:
``local_sbt.loop_velocity`` (the tension map as (B₂ + B B) S0, corrected
semi-normal equations) against ``loop_velocity_blocks`` (column blocks through
two (M, M) projections and Householder QR: the code before this change),
registered here as a second model type.  The two are run alternately,
``--repeats`` times each, best wall time kept, so both see the same machine
load.  Prints wall times (best of the repeats), the speed-up (of the best and of
the medians), the work counts (equal when both
paths take the same steps) and the terminal difference.

``--baseline REV`` compares against the package as of git revision REV instead of the
dense path (``bench_kernels.import_baseline``: its own model, Jacobian and driver, in
the same process); the rows then also carry both terminal tilts
(``diagnostics.tilt_deg``) and their difference.
"""
import argparse
import collections
import importlib
import json
import time

import numpy as np

import loopsim
from bench_kernels import import_baseline
from loopsim import diagnostics, shapes
from loopsim.models import (auxiliary, implements, jacobian, local_sbt, monitored_errors, rhs,
                            steady_invariants)

#: The previous dense path as its own model type (same fields as LoopProblem).
DenseLoopProblem = collections.namedtuple("DenseLoopProblem", local_sbt.LoopProblem._fields)


@implements(rhs, DenseLoopProblem)
def _dense_rhs(problem, y, dydt):
    k = y.shape[0] // 3
    local_sbt.loop_velocity_blocks(y.reshape((3, k)), problem.g0, problem.w, problem.ops,
                                   problem.ws, dydt.reshape((3, k)))


@implements(jacobian, DenseLoopProblem)
def _dense_jacobian(problem, y, f, jac, work_y, work_f):
    k = y.shape[0] // 3
    local_sbt.loop_jacobian(y.reshape((3, k)), problem.g0, problem.w, problem.ops, problem.ws,
                            jac)
    return 1


@implements(monitored_errors, DenseLoopProblem)
def _dense_errors(problem, y):
    x = y.reshape((3, y.shape[0] // 3))
    return (local_sbt.relative_length_error(x, problem.ops, problem.ws),
            local_sbt.spectral_tail(x), local_sbt.top_mode_share(x))


@implements(steady_invariants, DenseLoopProblem)
def _dense_invariants(problem, y):
    k = y.shape[0] // 3
    return local_sbt.shape_invariants(y.reshape((3, k)))


@implements(auxiliary, DenseLoopProblem)
def _dense_multiplier(problem, out):
    out[:] = problem.ws.tension


def run(problem, x0, t_end, rtol, package=loopsim):
    """radau5 from x0 to t_end at rtol (atol = rtol / 1000) with ``package``'s driver:
    (wall s, status, x, counts)."""
    driver = importlib.import_module(package.__name__ + ".integrators.driver")
    methods = importlib.import_module(package.__name__ + ".integrators")
    radau5, options = methods.RADAU5, methods.step_options(rtol, rtol * 1e-3)
    y_out = np.empty((1, x0.size))
    start = time.perf_counter()
    status, t, y, counts, _ = driver.integrate(radau5, problem, x0.ravel().copy(), 0.0, t_end,
                                               np.array([t_end]), options, y_out)
    return time.perf_counter() - start, int(status), y.reshape(x0.shape), counts


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default="100:60,150:45,150:80")
    parser.add_argument("--orders", default="16,24,32")
    parser.add_argument("--t-end", type=float, default=10.0)
    parser.add_argument("--rtol", type=float, default=1e-6)
    parser.add_argument("--repeats", type=int, default=2)
    parser.add_argument("--out")
    parser.add_argument("--baseline", metavar="REV")
    args = parser.parse_args()
    w = loopsim.defaults.DEFAULT_W
    # the comparator: (make_problem(g0, n), package), the dense path by default
    other = (lambda g0, n: DenseLoopProblem(g0, w, local_sbt.make_operators(n),
                                            local_sbt.make_workspace(n)), loopsim)
    if args.baseline:
        base = import_baseline(args.baseline)
        from loopsim_baseline.models import local_sbt as base_sbt

        other = (lambda g0, n: base_sbt.LoopProblem(g0, w, base_sbt.make_operators(n),
                                                    base_sbt.make_workspace(n)), base)
    fast = (lambda g0, n: local_sbt.LoopProblem(g0, w, local_sbt.make_operators(n),
                                                local_sbt.make_workspace(n)), loopsim)
    warm = shapes.initial_shape(4, np.radians(30.0), 1e-3, 0)
    for make, package in (fast, other):  # compile outside the timing
        run(make(60.0, 4), warm, 0.01, args.rtol, package)
    rows = []
    print(f"{'g0':>5} {'th0':>4} {'n':>3} {'dense_s':>8} {'fast_s':>8} {'speedup':>7} {'median':>7} "
          f"{'nfev':>7} {'njev':>5} {'nlu':>5} {'steps':>6} {'max|dx|':>8} {'|dtilt|':>9}")
    for case in args.cases.split(","):
        g0, theta0 = (float(v) for v in case.split(":"))
        for n in (int(v) for v in args.orders.split(",")):
            x0 = shapes.initial_shape(n, np.radians(theta0), 1e-3, 0)
            walls = {"dense": [], "fast": []}
            result = {}
            for _ in range(args.repeats):
                for name, (make, package) in (("dense", other), ("fast", fast)):
                    wall, status, x, counts = run(make(g0, n), x0, args.t_end, args.rtol,
                                                  package)
                    walls[name].append(wall)
                    result[name] = (status, x, counts)
            best = {name: min(times) for name, times in walls.items()}
            counts = result["fast"][2]
            row = dict(g0=g0, theta0=theta0, n=n, dense_s=best["dense"], fast_s=best["fast"],
                       speedup=best["dense"] / best["fast"], walls_dense=walls["dense"],
                       walls_fast=walls["fast"],
                       median_speedup=float(np.median(walls["dense"]) / np.median(walls["fast"])),
                       counts_fast=[int(c) for c in counts],
                       counts_dense=[int(c) for c in result["dense"][2]],
                       max_dx=float(np.abs(result["fast"][1] - result["dense"][1]).max()),
                       status=[result["fast"][0], result["dense"][0]],
                       tilt_fast_deg=diagnostics.tilt_deg(result["fast"][1]),
                       tilt_dense_deg=diagnostics.tilt_deg(result["dense"][1]))
            rows.append(row)
            print(f"{g0:>5g} {theta0:>4g} {n:>3} {row['dense_s']:>8.2f} {row['fast_s']:>8.2f} "
                  f"{row['speedup']:>7.2f} {row['median_speedup']:>7.2f} {counts[2]:>7} {counts[3]:>5} {counts[4]:>5} "
                  f"{counts[0] + counts[1]:>6} {row['max_dx']:>8.1e} "
                  f"{abs(row['tilt_fast_deg'] - row['tilt_dense_deg']):>9.1e}", flush=True)
    if args.out:
        with open(args.out, "w") as handle:
            json.dump(rows, handle, indent=1)


if __name__ == "__main__":
    main()
