"""Outcomes as distributions over a grid of points (docs/distributions.md, "A study").

Usage: python scripts/distribution_study.py [--runs runs/distributions] [--threads T]
                                            [--g0 30,60,100] [--theta0 30,60]
                                            [--max-seeds 32] [--check-seeds 16]

1. ``--seeds auto`` at ``--n auto`` (with twins) over the grid: every point gets seeds
   until it is deterministic, sharp or at --max-seeds (``RUNS/auto``);
2. the points that did not stop as deterministic again, with --check-seeds fixed seeds
   at 10x stricter rtol and atol (``RUNS/strict``, no twins), compared in distribution
   with the first sweep's seeds 0 .. --check-seeds - 1 (``loopsim.compare``);
3. prints the summary, the stop table and the comparison as Markdown, and draws
   ``RUNS/summary.png`` (P(3D) per point, tilt over seeds).

Every step resumes: re-run the same command after an interruption.
"""
import argparse
import os
import time

import loopsim
from loopsim import io, plots


def markdown(frame, columns, formats):
    head = "| " + " | ".join(columns) + " |\n|" + "---|" * len(columns) + "\n"
    rows = ["| " + " | ".join(formats.get(c, "{}").format(row[c]) for c in columns) + " |"
            for _, row in frame.iterrows()]
    return head + "\n".join(rows)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", default=os.path.join("runs", "distributions"))
    parser.add_argument("--threads", type=int, default=None)
    parser.add_argument("--g0", default="30,60,100")
    parser.add_argument("--theta0", default="30,60")
    parser.add_argument("--max-seeds", type=int, default=32)
    parser.add_argument("--check-seeds", type=int, default=16)
    args = parser.parse_args()
    g0 = [float(v) for v in args.g0.split(",")]
    theta0 = [float(v) for v in args.theta0.split(",")]

    started = time.perf_counter()
    auto_dir = os.path.join(args.runs, "auto")
    rows = loopsim.sweep(g0, theta0, auto_dir, n="auto", seeds="auto",
                         max_seeds=args.max_seeds, threads=args.threads, quiet=False)
    auto_s = time.perf_counter() - started
    stops = io.read_stop_table(auto_dir)
    cells = loopsim.summarize(rows)

    spread = stops[stops["stop_reason"] != "deterministic"]
    strict_s = 0.0
    comparison = None
    if len(spread):
        started = time.perf_counter()
        strict_dir = os.path.join(args.runs, "strict")
        cases = [dict(g0=r.g0, theta0_deg=r.theta0_deg) for r in spread.itertuples()]
        strict = [loopsim.sweep([c["g0"]], [c["theta0_deg"]], os.path.join(
            strict_dir, f"g{c['g0']:g}_t{c['theta0_deg']:g}"), n="auto",
            seeds=args.check_seeds, rtol=1e-7, atol=1e-10, twin=False,
            threads=args.threads, quiet=False) for c in cases]
        strict_s = time.perf_counter() - started
        import pandas as pd

        strict = pd.concat(strict, ignore_index=True)
        first = rows[rows["seed"] < args.check_seeds]
        comparison = loopsim.compare(first, strict, by=["g0", "theta0_deg"])

    fig = plots.distribution_summary(cells, rows)
    plots.save(fig, os.path.join(args.runs, "summary.png"), dpi=150)
    print(f"\nseeds auto: {len(rows)} runs, {auto_s:.0f} s; strict check: {strict_s:.0f} s")
    print("\n" + markdown(stops, ["g0", "theta0_deg", "seeds", "rounds", "stop_reason",
                                  "p_halfwidth", "tilt_halfwidth_deg"],
                          {"p_halfwidth": "{:.3f}", "tilt_halfwidth_deg": "{:.2f}"}))
    print("\n" + markdown(cells, ["g0", "theta0_deg", "seeds", "determined", "p_stable",
                                  "p_in_plane", "p_3d", "tilt_median", "tilt_q25", "tilt_q75",
                                  "tilt_median_low", "tilt_median_high", "aspect_median"],
                          {c: "{:.3g}" for c in ["p_stable", "p_in_plane", "p_3d"]}
                          | {c: "{:.2f}" for c in ["tilt_median", "tilt_q25", "tilt_q75",
                                                   "tilt_median_low", "tilt_median_high"]}
                          | {"aspect_median": "{:.3f}"}))
    if comparison is not None:
        print("\n" + markdown(comparison, ["g0", "theta0_deg", "seeds_a", "seeds_b",
                                           "tilt_ks_p", "aspect_ks_p", "regime_p",
                                           "tilt_wasserstein", "verdict"],
                              {"tilt_ks_p": "{:.2f}", "aspect_ks_p": "{:.2f}",
                               "regime_p": "{:.2f}", "tilt_wasserstein": "{:.2f}"}))


if __name__ == "__main__":
    main()
