"""The nonlocal model's cost against the local one: right-hand side and exact Jacobian per
call, and whole resolved trajectories, in one process.

Usage: python benchmarks/bench_nonlocal_trajectory.py [--orders 12,16,20,24]
       [--cases 100:60,30:60] [--slenderness 1e-3] [--out FILE.json]

* Per call (µs, best of three timed loops, one thread): ``models.rhs`` and
  ``models.jacobian`` (exact for both models) at order n on the start shape of
  g0 = 100, θ0 = 60°; ``fd_jac`` is what a forward-difference Jacobian would cost
  (3K right-hand sides, K = 2n + 1), the nonlocal model's Jacobian before the exact one.
* Trajectories: ``simulate(g0, θ0, n="auto", method="radau5", twin=False)`` for each
  case, local, nonlocal, then local again (the smaller local time is used: the
  machine is shared); wall time, n_used, work counts, terminal tilt and aspect ratio,
  and the ratios of wall time and of wall time per accepted step.

Run it alone with OPENBLAS_NUM_THREADS=1 (the trajectories are one case each).
"""
import argparse
import json
import time

import numba
import numpy as np

import loopsim
from loopsim import models, shapes
from loopsim.models import jacobian, rhs
from scaling import per_call  # best of three timed loops, µs per call


@numba.njit(cache=True)
def _rhs(problem, y, dydt, repeats):
    for _ in range(repeats):
        rhs(problem, y, dydt)


@numba.njit(cache=True)
def _jacobian(problem, y, f, jac, work_y, work_f, repeats):
    for _ in range(repeats):
        jacobian(problem, y, f, jac, work_y, work_f)


def per_call_costs(n, eps):
    """{model: (rhs µs, jacobian µs)} at order n."""
    y = shapes.start_shape(60.0, n, None, 0, None, None)[0].ravel().copy()
    out = {}
    for name, model in (("local", models.LOCAL), ("nonlocal", models.choose("nonlocal", eps))):
        problem = models.make_problem(model, n, 100.0, 10.0)
        f, jac = np.empty_like(y), np.empty((y.size, y.size))
        _rhs(problem, y, f, 1)
        repeats = max(5, int(2e5 / y.size ** 2))
        out[name] = (per_call(_rhs, (problem, y, f), 20 * repeats),
                     per_call(_jacobian, (problem, y, f, jac, np.empty_like(y),
                                          np.empty_like(y)), repeats))
    return out


def trajectory(g0, theta0, **model):
    start = time.perf_counter()
    result = loopsim.simulate(g0, theta0, n="auto", method="radau5", twin=False, **model)
    return dict(wall_s=time.perf_counter() - start, n_used=result.n_used,
                steps=int(result.steps_accepted), rejected=int(result.steps_rejected),
                nfev=int(result.nfev), njev=int(result.njev),
                tilt_deg=float(result.end_state["theta_final_deg"]),
                aspect_ratio=float(result.end_state["aspect_ratio"]), resolved=result.resolved)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--orders", default="12,16,20,24")
    parser.add_argument("--cases", default="100:60,30:60", help="g0:theta0 pairs")
    parser.add_argument("--slenderness", type=float, default=1e-3)
    parser.add_argument("--out", help="also write the rows as JSON")
    args = parser.parse_args()
    rows = {"per_call": [], "trajectories": []}
    print(f"{'n':>3} {'local rhs':>10} {'nonlocal rhs':>13} {'ratio':>6} {'local jac':>10} "
          f"{'nonlocal jac':>13} {'ratio':>6} {'jac/rhs':>8} {'fd_jac/rhs':>10}")
    for n in (int(v) for v in args.orders.split(",")):
        cost = per_call_costs(n, args.slenderness)
        (lr, lj), (nr, nj) = cost["local"], cost["nonlocal"]
        k = 2 * n + 1
        print(f"{n:3d} {lr:10.1f} {nr:13.1f} {nr / lr:6.2f} {lj:10.1f} {nj:13.1f} "
              f"{nj / lj:6.2f} {nj / nr:8.1f} {3 * k:10d}")
        rows["per_call"].append(dict(n=n, local_rhs_us=lr, nonlocal_rhs_us=nr,
                                     local_jac_us=lj, nonlocal_jac_us=nj))
    nonlocal_model = dict(model="nonlocal", slenderness=args.slenderness)
    loopsim.simulate(100.0, 60.0, n=6, t_span=(0.0, 0.01), twin=False, method="radau5")
    loopsim.simulate(100.0, 60.0, n=6, t_span=(0.0, 0.01), twin=False, method="radau5",
                     **nonlocal_model)  # compiled before anything is timed
    for case in args.cases.split(","):
        g0, theta0 = (float(v) for v in case.split(":"))
        first = trajectory(g0, theta0)
        nonlocal_run = trajectory(g0, theta0, **nonlocal_model)
        second = trajectory(g0, theta0)
        local = min(first, second, key=lambda r: r["wall_s"])
        for name, run in (("local", local), (f"nonlocal eps={args.slenderness:g}", nonlocal_run)):
            print(f"g0 = {g0:g}, theta0 = {theta0:g}, {name}: {run}")
        ratio = nonlocal_run["wall_s"] / local["wall_s"]
        per_step = ratio * local["steps"] / nonlocal_run["steps"]
        print(f"  wall ratio {ratio:.1f}x, per accepted step {per_step:.1f}x")
        rows["trajectories"].append(dict(g0=g0, theta0=theta0, local=local,
                                         nonlocal_=nonlocal_run, ratio=ratio,
                                         per_step_ratio=per_step))
    if args.out:
        with open(args.out, "w") as handle:
            json.dump(rows, handle, indent=1)


if __name__ == "__main__":
    main()
