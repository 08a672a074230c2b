"""Outcomes as distributions over a grid of points (docs/distributions.md, the studies).

Usage: python scripts/distribution_study.py [--runs runs/distributions] [--threads T]
                                            [--g0 30,60,100] [--theta0 30,60]
                                            [--max-seeds 32]
                                            [--check tolerance|resolution]
                                            [--check-seeds 16] [--check-n 32]
                                            [--check-g0 SPEC] [--check-theta0 SPEC]

1. ``--seeds auto`` at ``--n auto`` (with twins) over the grid (``--g0`` and ``--theta0``
   as ``loopsim sweep`` takes them: ``10:150:8`` or ``30,60``): every point gets seeds
   until it is deterministic, sharp or at --max-seeds (``RUNS/auto``);
2. the points that did not stop as deterministic (those at --check-g0 and --check-theta0
   only, when given) again, with --check-seeds fixed seeds and no twins (``RUNS/<check>``), either at
   10x stricter rtol and atol (``--check tolerance``) or at the fixed order --check-n
   (``--check resolution``), compared in distribution (``loopsim.compare``) with the
   first sweep's seeds 0 .. --check-seeds - 1 (the same starts) or, for the resolution
   check, all its seeds (the start at --check-n differs in its higher modes);
3. writes the summary (``RUNS/summary.parquet``) and the comparison
   (``RUNS/compare-<check>.parquet``), prints them and the stop table as Markdown, and
   draws ``RUNS/summary.png`` (P(3D) per point, tilt and aspect ratio over seeds).

Every step resumes: re-run the same command after an interruption.
"""
import argparse
import os
import time

import pandas as pd

import loopsim
from loopsim import io, sweeps
from loopsim.cli.common import print_and_write, save_distribution_figure

CHECKS = {"tolerance": dict(rtol=1e-7, atol=1e-10), "resolution": {}}


def markdown(frame, columns, formats):
    head = "| " + " | ".join(columns) + " |\n|" + "---|" * len(columns) + "\n"
    rows = ["| " + " | ".join(formats.get(c, "{}").format(row[c]) for c in columns) + " |"
            for _, row in frame.iterrows()]
    return head + "\n".join(rows)


def check_cells(stops, g0, theta0):
    """The cells to check: not deterministic, and at one of ``g0`` and ``theta0`` when
    given (None: any)."""
    cells = stops[stops["stop_reason"] != "deterministic"]
    for column, values in (("g0", g0), ("theta0_deg", theta0)):
        if values is not None:
            cells = cells[cells[column].isin(values)]
    return [dict(g0=r.g0, theta0_deg=r.theta0_deg) for r in cells.itertuples()]


def run_check(cells, args):
    """Each cell again with --check-seeds seeds and no twins, as --check says."""
    options = dict(CHECKS[args.check], twin=False, threads=args.threads, quiet=False)
    if args.check == "resolution":
        options.update(n=args.check_n, method="auto")
    else:
        options.update(n="auto")
    directory = os.path.join(args.runs, args.check)
    return pd.concat([
        loopsim.sweep([c["g0"]], [c["theta0_deg"]],
                      os.path.join(directory, f"g{c['g0']:g}_t{c['theta0_deg']:g}"),
                      seeds=args.check_seeds, **options)
        for c in cells], ignore_index=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", default=os.path.join("runs", "distributions"))
    parser.add_argument("--threads", type=int, default=None)
    parser.add_argument("--g0", default="30,60,100")
    parser.add_argument("--theta0", default="30,60")
    parser.add_argument("--max-seeds", type=int, default=32)
    parser.add_argument("--check", choices=sorted(CHECKS), default="tolerance")
    parser.add_argument("--check-seeds", type=int, default=16)
    parser.add_argument("--check-n", type=int, default=32)
    parser.add_argument("--check-g0", default=None)
    parser.add_argument("--check-theta0", default=None)
    args = parser.parse_args()
    g0 = sweeps.parse_values(args.g0, "--g0")
    theta0 = sweeps.parse_values(args.theta0, "--theta0")
    check_g0, check_theta0 = (
        None if text is None else sweeps.parse_values(text, name)
        for text, name in ((args.check_g0, "--check-g0"), (args.check_theta0, "--check-theta0")))

    started = time.perf_counter()
    auto_dir = os.path.join(args.runs, "auto")
    rows = loopsim.sweep(g0, theta0, auto_dir, n="auto", seeds="auto",
                         max_seeds=args.max_seeds, threads=args.threads, quiet=False)
    auto_s = time.perf_counter() - started
    stops = io.read_stop_table(auto_dir)
    cells = loopsim.summarize(rows)

    started = time.perf_counter()
    comparison = None
    checked = check_cells(stops, check_g0, check_theta0)
    if checked:
        again = run_check(checked, args)
        # the tolerance check repeats the same starts (seeds 0 .. K-1); at another order
        # the start differs in its modes above 16, so every seed of the first sweep counts
        first = rows[rows["seed"] < args.check_seeds] if args.check == "tolerance" else rows
        comparison = loopsim.compare(first, again, by=["g0", "theta0_deg"])
    check_s = time.perf_counter() - started

    save_distribution_figure(cells, rows, os.path.join(args.runs, "summary.png"))
    print(f"\nseeds auto: {len(rows)} runs, {auto_s:.0f} s, "
          f"{rows['wall_s'].sum():.0f} s summed case time; "
          f"{args.check} check of {len(checked)} points: {check_s:.0f} s")
    print_and_write(cells, os.path.join(args.runs, "summary.parquet"),
                    dict(cells.attrs["loopsim_summary"], summary_of=os.path.abspath(auto_dir)),
                    ["g0", "theta0_deg", "seeds", "p_3d", "tilt_median"])
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
        print_and_write(comparison, os.path.join(args.runs, f"compare-{args.check}.parquet"),
                        dict(compared=f"{args.check} check"), ["g0", "theta0_deg", "verdict"])
        print("\n" + markdown(comparison, ["g0", "theta0_deg", "seeds_a", "seeds_b",
                                           "tilt_ks_p", "aspect_ks_p", "regime_p",
                                           "tilt_wasserstein", "verdict"],
                              {"tilt_ks_p": "{:.2f}", "aspect_ks_p": "{:.2f}",
                               "regime_p": "{:.2f}", "tilt_wasserstein": "{:.2f}"}))


if __name__ == "__main__":
    main()
