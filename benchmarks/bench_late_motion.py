"""What the late-motion samples cost: a run with its 401 samples against the same run
without output.

Usage: python benchmarks/bench_late_motion.py [--rounds 5] [--cases 150:45:16:2,60:30:16:10]

Each case (g0:θ0:n:t_end, radau5 at the default tolerances, seed 0) runs in turn
without output (``refinement.integrate_case`` with output only at t0 and t_end: the
driver compiled without dense output) and with the ``late_motion.MOTION_SAMPLES``
sample times (dense output), ``--rounds`` times each, interleaved; then
``late_motion.late_motion`` on the samples alone.  It prints the fastest and median wall
times, their ratio, and checks that both runs took the same steps (nfev, x_final bit for
bit).  The samples cost no right-hand-side evaluations; what they cost is the dense
output's polynomial and the copy, and the 401 3x3 eigenproblems afterwards.
"""
import argparse
import statistics
import time

import numpy as np

from loopsim import integrators, late_motion, outcomes, refinement, shapes
from loopsim.defaults import DEFAULT_ATOL, DEFAULT_RTOL


def run(case, times):
    g0, theta0, n, t_end = case
    x0 = shapes.start_shape(theta0, n, 1e-3, 0)[0]
    options = integrators.step_options(DEFAULT_RTOL, DEFAULT_ATOL, max_steps=10**6)
    start = time.perf_counter()
    result = refinement.integrate_case(integrators.METHODS["radau5"], g0, 10.0, x0, 0.0,
                                       t_end, times, options, (n,), np.inf)
    return time.perf_counter() - start, result


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--cases", default="150:45:16:2,60:30:16:10")
    args = parser.parse_args()
    cases = [tuple(float(v) if i != 2 else int(v) for i, v in enumerate(c.split(":")))
             for c in args.cases.split(",")]
    print("| case (g0, θ0, n, t_end) | nfev | no output: min / median s | 401 samples: "
          "min / median s | ratio of mins | late_motion s |")
    print("|---|---|---|---|---|---|")
    for case in cases:
        ends = np.array([0.0, case[3]])
        samples = late_motion.sample_times(0.0, case[3])
        run(case, ends), run(case, samples)  # compiled before timing
        walls, last = {"ends": [], "samples": []}, {}
        for _ in range(args.rounds):
            for label, times in (("ends", ends), ("samples", samples)):
                wall, last[label] = run(case, times)
                walls[label].append(wall)
        plain, sampled = last["ends"], last["samples"]
        assert plain.counts.tolist() == sampled.counts.tolist()
        assert np.array_equal(plain.x_final, sampled.x_final)
        start = time.perf_counter()
        late_motion.late_motion(samples, sampled.x_out, 0.0, case[3], sampled.t_final,
                                sampled.x_final, True, False, outcomes.Thresholds())
        analysis = time.perf_counter() - start
        nfev = int(plain.counts[integrators.COUNTS.index("nfev")])
        print(f"| {case} | {nfev} | {min(walls['ends']):.3f} / "
              f"{statistics.median(walls['ends']):.3f} | {min(walls['samples']):.3f} / "
              f"{statistics.median(walls['samples']):.3f} | "
              f"{min(walls['samples']) / min(walls['ends']):.3f} | {analysis:.4f} |")


if __name__ == "__main__":
    main()
