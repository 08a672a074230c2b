"""Ensemble benchmark: cases per second, parallel efficiency, early stopping, load balance.

Usage: python benchmarks/bench_ensemble.py [--g0 10:350:8] [--theta0 6:90:8] [--n 6]

Runs the same paper-like grid (n = 6, t_end = 10) as full sweeps with 1 and
2 threads, with and without early stopping, and prints cases per second,
the 2-thread speed-up, the early-stop speed-up with the regimes it changed,
and the cost split between regimes.  Then the load-balance effect: one batch
of all cases (t_end = 3) dealt onto the 2 threads' lanes in grid order,
against in order of decreasing q0 (what loopsim does).
"""
import argparse
import math
import tempfile
import time

import numba
import numpy as np

import loopsim
from loopsim import batch, integrators, shapes, sweeps
from loopsim.models import local_sbt


def timed_sweep(config, threads):
    with tempfile.TemporaryDirectory() as out:
        start = time.perf_counter()
        frame = sweeps.run_sweep(config, out, threads=threads, quiet=True)
        return time.perf_counter() - start, frame


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--g0", default="10:350:8")
    parser.add_argument("--theta0", default="6:90:8")
    parser.add_argument("--n", type=int, default=6)
    parser.add_argument("--t-end", type=float, default=10.0)
    parser.add_argument("--method", default="rkf45", help="integrator")
    args = parser.parse_args()
    cases = sweeps.grid_cases(sweeps.parse_values(args.g0, "--g0"),
                              sweeps.parse_values(args.theta0, "--theta0"), [args.n], 1)
    warm = sweeps.SweepConfig(cases=cases[:2], t_end=0.01, method=args.method)
    timed_sweep(warm, 2)  # compile

    print(f"# {args.method}: {len(cases)} cases, n = {args.n}, t_end = {args.t_end}, "
          f"{numba.config.NUMBA_NUM_THREADS} cores available")
    print(f"{'threads':>7} {'early_stop':>10} {'wall_s':>8} {'cases/s':>8}")
    results = {}
    for early in (False, True):
        config = sweeps.SweepConfig(cases=cases, t_end=args.t_end, early_stop=early,
                                    method=args.method)
        for threads in (1, 2):
            wall, frame = timed_sweep(config, threads)
            results[threads, early] = (wall, frame)
            print(f"{threads:>7} {str(early):>10} {wall:>8.1f} {len(cases) / wall:>8.2f}", flush=True)
    for early in (False, True):
        speedup = results[1, early][0] / results[2, early][0]
        print(f"# 2-thread speed-up (early_stop={early}): {speedup:.2f}x, "
              f"parallel efficiency {speedup / 2:.0%}")
    full, early = results[2, False][1], results[2, True][1]
    changed = (full["regime"] != early["regime"]).sum()
    print(f"# early stop: {results[2, False][0] / results[2, True][0]:.2f}x faster (2 threads); "
          f"{(early['stop_reason'] == 'steady').sum()}/{len(cases)} cases stopped early, mean "
          f"t_final {early['t_final'].mean():.2f}; regime changed in {changed} case(s); "
          f"max |d aspect ratio| {np.abs(full['aspect_ratio'] - early['aspect_ratio']).max():.1e}, "
          f"max |d tilt| {np.abs(full['theta_final_deg'] - early['theta_final_deg']).max():.1e} deg")
    print("# cost split by regime (full runs):")
    total = full["nfev"].sum()
    for regime, rows in full.groupby("regime"):
        print(f"#   {regime:>8}: {len(rows):3d} cases, mean nfev {rows['nfev'].mean():9.0f}, "
              f"{rows['nfev'].sum() / total:.0%} of all work")

    operators = local_sbt.make_operators(args.n)
    x0 = np.array([shapes.initial_shape(args.n, math.radians(c["theta0_deg"]), c["perturbation"],
                                         c["seed"]).ravel() for c in cases])
    g0 = [c["g0"] for c in cases]
    options = sweeps.SweepConfig(cases=cases, early_stop=False).step_options()
    method_id = integrators.METHODS[args.method]
    numba.set_num_threads(2)
    q0 = [loopsim.stability_parameter(c["g0"], c["theta0_deg"]) for c in cases]
    walls = {}
    for label, cost in (("grid order", None), ("by q0", q0)):
        start = time.perf_counter()
        batch.integrate_batch(method_id, operators, np.column_stack([g0, np.full(len(g0), 10.0)]),
                              x0, 3.0, options, cost=cost)
        walls[label] = time.perf_counter() - start
    print(f"# load balance, 2 threads, one batch, t_end = 3: lanes in grid order "
          f"{walls['grid order']:.1f} s, by decreasing q0 {walls['by q0']:.1f} s "
          f"({walls['grid order'] / walls['by q0']:.2f}x)")


if __name__ == "__main__":
    main()
