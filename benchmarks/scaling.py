"""Scaling in n: cost per RHS evaluation and per trajectory, where the time goes,
and whether the step is limited by stiffness or accuracy.

Usage: python benchmarks/scaling.py [--orders 4,6,8,10,12,16] [--t-end 0.5]

For each n (in-plane case g0 = 60, θ0 = 30°):
* µs per RHS evaluation, split into the maps (the affine map T -> ε of
  ``local_sbt.length_rate_operator``, with the shape on the grid), the
  least-squares tension solve (``linalg.least_squares_normal``) and the rest
  (velocity synthesis), each timed in its own compiled loop;
* one trajectory over t_end: steps, mean step against the stiffness bound
  3.7/λmax, λmax = 1.5 n²(n² − 1), and the share of wall time spent outside
  RHS evaluations (the stepper);
then power-law exponents fitted over the larger orders.
"""
import argparse
import time

import numba
import numpy as np

import loopsim
from loopsim import models, shapes
from loopsim.linalg import least_squares_normal
from loopsim.models import local_sbt as physics


@numba.njit(cache=True)
def _time_maps(x, g0, w, ops, ws, repeats):
    for _ in range(repeats):
        physics.shape_on_grid(x, ops, ws)
        physics.length_rate_operator(g0, w, ops, ws)


@numba.njit(cache=True)
def _time_solve(ops, ws, repeats):
    for _ in range(repeats):  # the block is read, not destroyed
        least_squares_normal(ws.length_rate, ops.column_scale, ws.tension, ws.gram,
                             ws.residual, ws.correction)


@numba.njit(cache=True)
def _time_rhs(problem, y, dydt, repeats):
    for _ in range(repeats):
        models.rhs(problem, y, dydt)


def per_call(fn, args, repeats):
    fn(*args, 1)
    best = np.inf
    for _ in range(3):
        start = time.perf_counter()
        fn(*args, repeats)
        best = min(best, time.perf_counter() - start)
    return 1e6 * best / repeats


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--orders", default="4,6,8,10,12,16")
    parser.add_argument("--t-end", type=float, default=0.5)
    args = parser.parse_args()
    orders = [int(v) for v in args.orders.split(",")]
    g0, w = 60.0, 10.0
    loopsim.simulate(g0, 30.0, n=4, t_span=(0, 0.01))  # load the compiled driver before timing
    rows = []
    print(f"{'n':>3} {'us/rhs':>8} {'maps':>7} {'lstsq':>7} {'rest':>6} {'steps':>7} "
          f"{'mean_h':>9} {'3.7/lmax':>9} {'traj_s':>8} {'stepper%':>8}")
    for n in orders:
        x = shapes.initial_shape(n, np.radians(30.0), 1e-3, 0)
        problem = physics.make_problem(n, g0, w)
        ops, ws = problem.ops, problem.ws
        u = np.empty_like(x)
        repeats = max(200, int(2e5 / n**3))
        rhs = per_call(_time_rhs, (problem, x.reshape(-1), u.reshape(-1)), repeats)
        maps = per_call(_time_maps, (x, g0, w, ops, ws), repeats)
        physics.shape_on_grid(x, ops, ws)
        physics.length_rate_operator(g0, w, ops, ws)
        solve = per_call(_time_solve, (ops, ws), repeats)
        result = loopsim.simulate(g0, 30.0, n=n, t_span=(0, args.t_end))
        stepper = 1 - result.nfev * rhs * 1e-6 / result.wall_s
        bound = 3.7 / (1.5 * n**2 * (n**2 - 1))
        rows.append((n, rhs, result.wall_s * 10 / args.t_end))
        print(f"{n:>3} {rhs:>8.2f} {maps:>7.2f} {solve:>7.2f} {rhs - maps - solve:>6.2f} "
              f"{result.steps_accepted:>7} {result.t_final / result.steps_accepted:>9.2e} "
              f"{bound:>9.2e} {result.wall_s:>8.3f} {100 * stepper:>7.0f}%", flush=True)
    big = [r for r in rows if r[0] >= 8]
    if len(big) >= 2:
        logn = np.log([r[0] for r in big])
        rhs_exp = np.polyfit(logn, np.log([r[1] for r in big]), 1)[0]
        traj_exp = np.polyfit(logn, np.log([r[2] for r in big]), 1)[0]
        print(f"# fitted over n >= 8: time per RHS ~ n^{rhs_exp:.2f}, "
              f"time per unit simulated time ~ n^{traj_exp:.2f} (paper's crude estimate: n^7)")


if __name__ == "__main__":
    main()
