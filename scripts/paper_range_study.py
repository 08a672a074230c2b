"""The paper's range as probabilities (docs/distributions.md, "The paper's range as
probabilities").

Usage: python scripts/paper_range_study.py [--runs runs] [--threads T] [--data data]
                                           [--figure docs/figures/paper_range.png]
                                           [--max-seeds 8] [--quick]

The paper's Fig. 5 grid is ``--g0 10:350:15 --theta0 6:90:15`` (225 cells).  This study
runs, with ``--seeds auto --n auto`` (twins, at most --max-seeds seeds, each sampled
cell checked in distribution against up to 8 seeds at 10x stricter tolerances):

* ``paper_range_low``: every cell with g0 <= 131.4 (the grid's first six g0 values x
  its 15 tilts, 90 cells);
* ``paper_range_band`` and ``paper_range_band18``: the cells with g0 > 150 at θ0 = 6 and
  12° (18 cells, q0 = 5.4-24.3), and at 18° (9 cells, q0 = 16.0-36.1), the band where the
  regime can be mixed (the main job's grid found mixed cells only at q0 = 11.7-36.1);
  two sweeps, because a cell at 18° costs minutes a sample above g0 = 250 and the rounds
  of one sweep wait for their slowest cell;
* ``paper_range_band24``, ``paper_range_mid30``, ``paper_range_mid42`` and
  ``paper_range_mid54``: g0 = 155.7-228.6 at θ0 = 24° (4 cells), 30° and 36°, 42° and
  48°, 54° and 60° (8 cells each), whose samples cost seconds (0.2-68 s on average per
  cell);
* ``paper_range_mid66``: g0 = 155.7-228.6 at 66° and 72° (8 cells).

The other cells (g0 > 150 and θ0 >= 24°, except those) are not run: one of their samples
costs minutes (docs/distributions.md gives the measured costs and the projection).

Writes ``DATA/paper_range_summary.parquet`` (``loopsim summary`` of every part's rows,
one row per cell) and ``DATA/paper_range_stops.parquet`` (their stop tables: why each
cell stopped, and its distribution check), each column described (``loopsim.columns``);
prints the cost (the runs' ``wall_s`` scaled by (nfev + twin_nfev) / nfev, and the check
runs') and the cells that are certain, mixed, and those where seed 0's regime is not
the most probable one; draws the figure (``loopsim summary --figure``'s panels).
Every sweep resumes: re-run the same command after an interruption.  ``--read-only``
tabulates the parts that have finished and names the others.
"""
import argparse
import os
import sys

import numpy as np
import pandas as pd

from loopsim import cli, columns, outcome_statistics, storage
from loopsim.cli.common import print_and_write, use_agg
from loopsim.figures import save_distribution_figure

#: The paper's grid: g0 = 10..350 in 15 values, θ0 = 6..90° in 15.
G0 = np.linspace(10.0, 350.0, 15)
THETA0 = np.linspace(6.0, 90.0, 15)
#: The figure's resolution: three wide panels under 300 kB.
FIGURE_DPI = 120
#: The parts run: (name, g0 values, θ0 values).
PARTS = (("paper_range_low", G0[:6], THETA0), ("paper_range_band", G0[6:], THETA0[:2]),
         ("paper_range_band18", G0[6:], THETA0[2:3]),
         ("paper_range_band24", G0[6:10], THETA0[3:4]),
         ("paper_range_mid30", G0[6:10], THETA0[4:6]),
         ("paper_range_mid42", G0[6:10], THETA0[6:8]),
         ("paper_range_mid54", G0[6:10], THETA0[8:10]),
         ("paper_range_mid66", G0[6:10], THETA0[10:12]))
QUICK_PARTS = (("paper_range_low", G0[:2], THETA0[::7]), ("paper_range_band", G0[6:7],
                                                            THETA0[:1]))


def values(array):
    return ",".join(repr(float(v)) for v in array)


def run_part(path, g0, theta0, threads, max_seeds, quick):
    """``loopsim sweep --seeds auto`` of one part into ``path`` (resumes)."""
    args = ["sweep", "--g0", values(g0), "--theta0", values(theta0), "--n", "auto",
            "--seeds", "auto", "--max-seeds", str(max_seeds), "--threads", str(threads),
            "--out", path, "--quiet"]
    if quick:
        args += ["--t-end", "0.5", "--n-max", "8"]
    print("$ loopsim " + " ".join(args), flush=True)
    code = cli.main(args)
    if code not in (0, 1):
        sys.exit(f"paper_range_study: the sweep into {path} exited with status {code}")


def cost(frame, checks):
    """(summed seconds of the runs with their twins, of the check runs)."""
    nfev = frame["nfev"].to_numpy(float).clip(1.0)
    twin = frame["twin_nfev"].fillna(0.0).to_numpy(float)
    runs = float((frame["wall_s"].to_numpy(float) * (1.0 + twin / nfev)).sum())
    return runs, float(checks["wall_s"].sum()) if len(checks) else 0.0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", default="runs")
    parser.add_argument("--data", default="data")
    parser.add_argument("--figure", default=os.path.join("docs", "figures", "paper_range.png"))
    parser.add_argument("--threads", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--max-seeds", type=int, default=8)
    parser.add_argument("--read-only", action="store_true",
                        help="run nothing: tabulate the parts that have finished (their stop "
                             "table written) and name the others")
    parser.add_argument("--quick", action="store_true",
                        help="a few cells, t = 0.5, n <= 8: exercises the script")
    args = parser.parse_args()
    frames, stops, checks = [], [], []
    for name, g0, theta0 in QUICK_PARTS if args.quick else PARTS:
        path = os.path.join(args.runs, name)
        if not args.read_only:
            run_part(path, g0, theta0, args.threads, args.max_seeds, args.quick)
        elif not os.path.isfile(os.path.join(path, storage.STOPS_FILE)):
            print(f"{name}: not finished, left out ({len(g0) * len(theta0)} cells)")
            continue
        frames.append(storage.read_seeds_auto(path).assign(part=name))
        stops.append(storage.read_stop_table(path).assign(part=name))
        check = os.path.join(path, storage.CHECK_DIR)
        if os.path.isdir(check):
            checks.append(storage.read_results(check))
    frame = pd.concat(frames, ignore_index=True)
    stop = pd.concat(stops, ignore_index=True).drop(columns="part")
    stop["n"] = stop["n"].astype("int64")
    check_rows = pd.concat(checks, ignore_index=True) if checks else pd.DataFrame()
    table = outcome_statistics.summarize(frame.drop(columns="part"))
    os.makedirs(args.data, exist_ok=True)
    meta = dict(summary_of=" + ".join(sorted(set(frame["part"]))))
    shown = ["g0", "theta0_deg", "seeds", "determined", "p_stable", "p_in_plane", "p_3d",
             "tilt_median", "tilt_median_low", "tilt_median_high"]
    print_and_write(table, os.path.join(args.data, "paper_range_summary.parquet"), meta,
                    shown, declarations=columns.SUMMARY_COLUMNS)
    print_and_write(stop, os.path.join(args.data, "paper_range_stops.parquet"), meta,
                    ["g0", "theta0_deg", "seeds", "stop_reason", "runs", "check_verdict",
                     "check_tilt_wasserstein"], declarations=columns.STOP_COLUMNS)
    runs_s, check_s = cost(frame, check_rows)
    print(f"\ncost: {len(frame)} runs {runs_s:.0f} s with their twins, {len(check_rows)} "
          f"check runs {check_s:.0f} s; {(runs_s + check_s) / 3600:.2f} h of one core")
    p = table[["p_stable", "p_in_plane", "p_3d"]].to_numpy(float)
    certain = (p.max(axis=1) == 1.0)
    print(f"cells: {len(table)}; certain {int(certain.sum())} (stable "
          f"{int((table.p_stable == 1).sum())}, in-plane {int((table.p_in_plane == 1).sum())}, "
          f"3D {int((table.p_3d == 1).sum())}); mixed {int((~certain).sum())}")
    seed0 = frame[frame["seed"] == 0].set_index(["g0", "theta0_deg"])["regime"]
    labels = np.array(["stable", "in-plane", "3d", "failed"])
    cells = pd.MultiIndex.from_frame(table[["g0", "theta0_deg"]])
    share = pd.DataFrame(table[["p_stable", "p_in_plane", "p_3d", "p_failed"]].to_numpy(float),
                         index=cells, columns=labels)
    likeliest = pd.Series(["/".join(labels[row == row.max()]) for row in share.to_numpy()],
                          index=cells)
    misled = [(g, t, seed0[(g, t)], likeliest[(g, t)]) for g, t in cells
              if share.loc[(g, t), seed0[(g, t)]] < share.loc[(g, t)].max()]
    print(f"one run (seed 0) misleads (its regime less probable than another) at "
          f"{len(misled)}:")
    for g, t, one, most in misled:
        print(f"  ({g:.1f}, {t:g}°): seed 0 {one}, most probable {most}")
    print("by regime of the most probable outcome (a/b: a tie): "
          + ", ".join(f"{k} {v}" for k, v in likeliest.value_counts().items()))
    moving = table[table["steady"] < table["seeds"]]
    print(f"cells with seeds not steady at t_end (their tilt a snapshot): {len(moving)}; "
          f"runs not steady: {int((table['seeds'] - table['steady']).sum())} of "
          f"{int(table['seeds'].sum())}")
    for _, cell in moving.iterrows():
        print(f"  ({cell['g0']:.1f}, {cell['theta0_deg']:g}°): "
              f"{int(cell['seeds'] - cell['steady'])} of {int(cell['seeds'])}")
    if args.figure:
        use_agg()
        save_distribution_figure(table, frame.drop(columns="part"), args.figure, dpi=FIGURE_DPI)
        print(f"figure: {args.figure}")


if __name__ == "__main__":
    main()
