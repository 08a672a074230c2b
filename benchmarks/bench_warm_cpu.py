"""Warm runs in CPU seconds: what a compile-time change must not slow down.

Usage: OPENBLAS_NUM_THREADS=1 python benchmarks/bench_warm_cpu.py [--repeats 5]
                                                                  [--out FILE.json]

Runs each case once to load (or compile) its kernels, then ``--repeats`` times, and
prints the CPU time (``time.process_time``: user + system of this process, all its
threads) of each repeat, with the best and the median.  CPU time rather than wall time:
on a machine other jobs share, a run's wall time counts their time too.  The cases: the
paper's scheme (n = 6, rkf45, its twin), the default run (``--n auto``: radau5 up the
ladder, its twin) and a radau5 trajectory at n = 16 without twin.  To compare two
trees, run this script in each (``PYTHONPATH``), alternating, on one machine.
"""
import argparse
import json
import statistics
import time
import warnings

CASES = {
    "n6_rkf45_60_30": dict(g0=60.0, theta0_deg=30.0, n=6, method="rkf45"),
    "auto_60_30": dict(g0=60.0, theta0_deg=30.0),
    "radau5_n16_150_45_t2": dict(g0=150.0, theta0_deg=45.0, n=16, method="radau5",
                                 t_span=(0.0, 2.0), twin=False),
}


def cpu_seconds(run):
    """CPU seconds of one call of ``run`` (this process, every thread)."""
    start = time.process_time()
    run()
    return time.process_time() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--out", metavar="FILE.json")
    args = parser.parse_args()
    import loopsim

    warnings.simplefilter("ignore", loopsim.LoopsimWarning)
    rows = {}
    print(f"loopsim at {loopsim.__file__}")
    print(f"{'case':<22} {'best_cpu_s':>10} {'median':>8}  repeats")
    for name, kwargs in CASES.items():
        run = lambda: loopsim.simulate(**kwargs)  # noqa: E731
        run()  # kernels loaded (or compiled) once
        times = [cpu_seconds(run) for _ in range(args.repeats)]
        rows[name] = times
        print(f"{name:<22} {min(times):10.3f} {statistics.median(times):8.3f}  "
              + " ".join(f"{t:.3f}" for t in times), flush=True)
    if args.out:
        with open(args.out, "w") as handle:
            json.dump(dict(loopsim=loopsim.__file__, cpu_s=rows), handle, indent=1)


if __name__ == "__main__":
    main()
