"""Per trajectory at equal error: radau5 of this tree against the package at a git
revision (default 1a09d6c, the tree before the cheaper right-hand side and the step-control
changes), on hard 3D cases, over rtol, in one process.

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_trajectory.py \
        --cases 150:45,100:60 --orders 21,24 --out runs/bench_trajectory.json

Each run starts from the same shape at t = 0 (the seeded circle of ``shapes.initial_shape``
at order n) and runs to ``--t-end``; its error is the terminal tilt's distance from this
tree's radau5 at ``--reference-rtol`` from that same start.  The equal-error speed-up of a
baseline run is its wall time over this tree's wall time at the same error, interpolated
log-log along this tree's work-precision curve; the table prints counts (deterministic)
and the median of ``--repeats`` wall times, old and new alternating.
"""
import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import loopsim  # noqa: E402
from bench_kernels import import_baseline  # noqa: E402
from bench_paths import run  # noqa: E402
from loopsim import diagnostics, shapes  # noqa: E402
from loopsim.models import local_sbt  # noqa: E402

RTOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8)


def problem_of(package, g0, n):
    sbt = sys.modules[package.__name__ + ".models.local_sbt"]
    return sbt.LoopProblem(g0, loopsim.config.DEFAULT_W, sbt.make_operators(n),
                           sbt.make_workspace(n))


def equal_error_time(errors, times, error):
    """This tree's wall time at ``error``, interpolated log-log along its (error, time)
    points sorted by error; NaN outside their range."""
    order = np.argsort(errors)
    e, t = np.log(np.asarray(errors)[order]), np.log(np.asarray(times)[order])
    if not (e[0] <= np.log(error) <= e[-1]):
        return float("nan")
    return float(np.exp(np.interp(np.log(error), e, t)))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default="150:45,100:60")
    parser.add_argument("--orders", default="21,24")
    parser.add_argument("--t-end", type=float, default=2.0)
    parser.add_argument("--reference-rtol", type=float, default=1e-11)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--baseline", metavar="REV", default="1a09d6c")
    parser.add_argument("--out")
    args = parser.parse_args()
    base = import_baseline(args.baseline)
    import loopsim_baseline.models.local_sbt  # noqa: F401 - registers its model

    packages = {"new": loopsim, "old": base}
    warm = shapes.initial_shape(4, np.radians(30.0), 1e-3, 0)
    for package in packages.values():  # compile outside the timing
        run(problem_of(package, 60.0, 4), warm, 0.01, 1e-6, package)
    rows = []
    print("| g0 | θ0 | n | rtol | old nfev | new nfev | old rejected | new rejected "
          "| old s | new s | old error (deg) | new error (deg) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for case in args.cases.split(","):
        g0, theta0 = (float(v) for v in case.split(":"))
        for n in (int(v) for v in args.orders.split(",")):
            x0 = shapes.initial_shape(n, np.radians(theta0), 1e-3, 0)
            _, status, x_ref, _ = run(problem_of(loopsim, g0, n), x0, args.t_end,
                                      args.reference_rtol)
            reference = diagnostics.tilt_deg(x_ref)
            for rtol in RTOLS:
                row = dict(g0=g0, theta0=theta0, n=n, rtol=rtol, reference_tilt=reference)
                walls = {name: [] for name in packages}
                for _ in range(args.repeats):
                    for name, package in packages.items():
                        wall, status, x, counts = run(problem_of(package, g0, n), x0,
                                                      args.t_end, rtol, package)
                        walls[name].append(wall)
                        row.update({f"{name}_status": status,
                                    f"{name}_counts": [int(c) for c in counts],
                                    f"{name}_error": abs(diagnostics.tilt_deg(x) - reference)})
                for name in packages:
                    row[f"{name}_s"] = float(np.median(walls[name]))
                rows.append(row)
                print(f"| {g0:g} | {theta0:g} | {n} | {rtol:g} | {row['old_counts'][2]} | "
                      f"{row['new_counts'][2]} | {row['old_counts'][1]} | "
                      f"{row['new_counts'][1]} | {row['old_s']:.2f} | {row['new_s']:.2f} | "
                      f"{row['old_error']:.2e} | {row['new_error']:.2e} |", flush=True)
    print("\nequal-error speed-up (old wall / new wall at the old run's error):")
    speedups = []
    for key in sorted({(r["g0"], r["theta0"], r["n"]) for r in rows}):
        group = [r for r in rows if (r["g0"], r["theta0"], r["n"]) == key]
        errors = [max(r["new_error"], 1e-14) for r in group]
        times = [r["new_s"] for r in group]
        for r in group:
            new_time = equal_error_time(errors, times, max(r["old_error"], 1e-14))
            r["equal_error_speedup"] = r["old_s"] / new_time
            if np.isfinite(r["equal_error_speedup"]):
                speedups.append(r["equal_error_speedup"])
            print(f"  {key} rtol {r['rtol']:g}: old error {r['old_error']:.2e}, "
                  f"{r['equal_error_speedup']:.2f}x")
    if speedups:
        print(f"geometric mean {np.exp(np.mean(np.log(speedups))):.2f}x over {len(speedups)} "
              f"points (range {min(speedups):.2f}-{max(speedups):.2f})")
    if args.out:
        with open(args.out, "w") as handle:
            json.dump(rows, handle, indent=1)


if __name__ == "__main__":
    main()
