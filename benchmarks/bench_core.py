"""Core-solver benchmark: cost of one t = 10 trajectory against truncation order.

Usage: python benchmarks/bench_core.py [--orders 4,6,8,12] [--g0 60] [--theta0 30]

For each n: steps, rejections, RHS evaluations, wall seconds after JIT
warm-up (one core), µs per RHS evaluation, the mean step against the
stiffness estimate 3.7 / λmax with λmax = 1.5 n²(n² − 1), the error of the
terminal shape against an rtol = 1e-10 run at the same n (time-discretisation
error), and the speed-up over the paper's reported cost (n = 6: 900 s,
n = 8: 7200 s per t = 10).  Then the cold-start time of a fresh process with
an empty and with a warm Numba cache.
"""
import argparse
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

PAPER_SECONDS = {6: 900.0, 8: 7200.0}


def stiffness_step(n):
    return 3.7 / (1.5 * n**2 * (n**2 - 1))


def cold_start(cache_dir):
    code = "import loopsim; loopsim.simulate(60, 30, t_span=(0, 0.01))"
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    start = time.perf_counter()
    subprocess.run([sys.executable, "-c", code], env=env, check=True)
    return time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--orders", default="4,6,8,12")
    parser.add_argument("--g0", type=float, default=60.0)
    parser.add_argument("--theta0", type=float, default=30.0)
    parser.add_argument("--t-end", type=float, default=10.0)
    parser.add_argument("--rtol", type=float, default=1e-6)
    args = parser.parse_args()

    import loopsim

    loopsim.simulate(args.g0, args.theta0, n=4, t_span=(0, 0.01))  # JIT warm-up
    header = (f"{'n':>3} {'steps':>8} {'rejected':>8} {'rhs':>9} {'wall_s':>8} {'us/rhs':>7} "
              f"{'mean_h':>9} {'3.7/lmax':>9} {'err_shape':>9} {'vs_paper':>8}")
    print(f"# g0 = {args.g0}, theta0 = {args.theta0} deg, t_end = {args.t_end}, rtol = {args.rtol}")
    print(header)
    for n in map(int, args.orders.split(",")):
        run = dict(n=n, t_span=(0, args.t_end))
        result = loopsim.simulate(args.g0, args.theta0, rtol=args.rtol, **run)
        reference = loopsim.simulate(args.g0, args.theta0, rtol=1e-10, atol=1e-13, **run)
        error = np.abs(result.x_final - reference.x_final).max()
        mean_h = result.t_final / result.steps_accepted
        paper = PAPER_SECONDS.get(n)
        ratio = f"{paper / result.wall_s:8.0f}" if paper else f"{'-':>8}"
        print(f"{n:>3} {result.steps_accepted:>8} {result.steps_rejected:>8} {result.nfev:>9} "
              f"{result.wall_s:>8.3f} {1e6 * result.wall_s / result.nfev:>7.2f} "
              f"{mean_h:>9.2e} {stiffness_step(n):>9.2e} {error:>9.1e} {ratio}", flush=True)

    with tempfile.TemporaryDirectory() as cache:
        empty = cold_start(cache)
        warm = cold_start(cache)
    print(f"# cold start (new process, import + first t = 0.01 run): "
          f"empty cache {empty:.1f} s, warm cache {warm:.1f} s")


if __name__ == "__main__":
    main()
