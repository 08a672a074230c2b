"""The paper's range as probabilities (docs/studies/paper-range.md).

Usage: python scripts/paper_range_study.py [--runs runs] [--threads T] [--data data]
                                           [--figure docs/figures/paper_range.png]
                                           [--max-seeds 8] [--quick] [--read-only]
                                           [--top] [--parts NAME,...]

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

The other 72 cells (g0 > 150 and θ0 >= 24°, except those) are ``--top``'s parts, each
sample costing seconds to minutes (docs/studies/paper-range.md gives the measured costs):

* ``paper_range_top78``: g0 = 155.7-228.6 at θ0 = 78°, 84° and 90° (12 cells);
* ``paper_range_top24`` ... ``paper_range_top84``: g0 = 252.9-350 at θ0 = 24° and 30°,
  36° and 42°, ..., 84° and 90° (10 cells each).

Their sweeps go to ``data/paper_range_runs`` by default, a folder committed as parts
finish (finished ones whole, the running one as far as it got), so that the study
resumes on another machine where it stopped; their tables are
``DATA/paper_range_top_summary.parquet`` and ``DATA/paper_range_top_stops.parquet`` and
their figure ``docs/figures/paper_range_top.png``.  ``--parts`` runs only the parts named;
the tables and the figure cover every finished part.

Writes ``DATA/paper_range_summary.parquet`` (``loopsim summary`` of every part's rows,
one row per cell) and ``DATA/paper_range_stops.parquet`` (their stop tables: why each
cell stopped, and its distribution check), each column described (``loopsim.columns``);
prints the cost (the runs' ``wall_s`` scaled by (nfev + twin_nfev) / nfev, and the check
runs') and the cells that are certain, mixed, and those where seed 0's regime is not
the most probable one; draws the figure (``loopsim summary --figure``'s panels).
Every sweep resumes: re-run the same command after an interruption.  ``--read-only``
tabulates the parts that have finished and names the others (one line and exit status 1
where none has).

``--quick`` (a few cells, t = 0.5, n <= 8: it exercises the script) keeps everything it
writes in one folder of its own, ``runs/paper_range_quick/`` by default (its sweeps, both
tables and the figure), and refuses to write over the committed study's tables and figure
(exit status 2).

A partial run never shrinks a table: where the finished parts (with ``--read-only``; or
those finished and those to run) would cover fewer cells than a table already at the
place it would write (the committed 153-cell ``data/paper_range_summary.parquet``, say,
from a ``--runs`` folder holding one finished part), or than the committed table its
figure draws, the script refuses in one line, naming the table and the cells it would
lose, with exit status 2 and nothing written (checked before any sweep runs, and again
before writing).  It does not merge a partial run into a fuller table either: their
rows would come from different sweeps.  To tabulate a partial run, give ``--data`` and
``--figure`` other places; to replace a table on purpose, move it away first.
"""
import argparse
import os
import sys

import numpy as np
import pandas as pd

from loopsim import cli, columns, outcome_statistics, storage
from loopsim.cli.common import print_and_write, use_agg
from loopsim.figures import save_distribution_figure
from loopsim.stability import rest_window

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
#: The 72 cells the parts above leave out (``--top``), the cheapest part first.
TOP_PARTS = (("paper_range_top78", G0[6:10], THETA0[12:]),
             *((f"paper_range_top{THETA0[k]:.0f}", G0[10:], THETA0[k:k + 2])
               for k in range(3, 15, 2)))
QUICK_PARTS = (("paper_range_low", G0[:2], THETA0[::7]), ("paper_range_band", G0[6:7],
                                                            THETA0[:1]))
#: Where ``--quick`` writes by default: its sweeps, tables and figure.
QUICK_RUNS = os.path.join("runs", "paper_range_quick")
#: The study's committed outputs (relative to the repository, or to the working directory
#: the study runs in): ``--quick`` never writes over them.
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SUMMARY_FILE, STOPS_FILE = "paper_range_summary.parquet", "paper_range_stops.parquet"
TOP_SUMMARY_FILE = "paper_range_top_summary.parquet"
TOP_STOPS_FILE = "paper_range_top_stops.parquet"
#: Where ``--top`` keeps its sweeps by default: committed, so that the study resumes.
TOP_RUNS = os.path.join("data", "paper_range_runs")
COMMITTED = (os.path.join("data", SUMMARY_FILE), os.path.join("data", STOPS_FILE),
             os.path.join("docs", "figures", "paper_range.png"),
             os.path.join("data", TOP_SUMMARY_FILE), os.path.join("data", TOP_STOPS_FILE),
             os.path.join("docs", "figures", "paper_range_top.png"))


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


def parse_args(argv=None):
    """The command line, with the output places filled in (:func:`resolve_outputs`);
    ValueError (one line) where ``--quick`` would write over the committed study."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", default=None,
                        help=f"the sweeps' folder (default: runs; with --quick {QUICK_RUNS}; "
                             f"with --top {TOP_RUNS})")
    parser.add_argument("--data", default=None,
                        help="the tables' folder (default: data; with --quick --runs)")
    parser.add_argument("--figure", default=None,
                        help="the figure (default: docs/figures/paper_range.png; with --quick "
                             "RUNS/paper_range.png; with --top docs/figures/paper_range_top.png; "
                             "empty: none)")
    parser.add_argument("--threads", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--max-seeds", type=int, default=8)
    parser.add_argument("--read-only", action="store_true",
                        help="run nothing: tabulate the parts that have finished (their stop "
                             "table written) and name the others")
    parser.add_argument("--quick", action="store_true",
                        help="a few cells, t = 0.5, n <= 8: exercises the script (writes under "
                             f"{QUICK_RUNS} by default, never over the committed study)")
    parser.add_argument("--top", action="store_true",
                        help="the 72 cells the other parts leave out (sweeps under "
                             f"{TOP_RUNS} by default, committed as they finish)")
    parser.add_argument("--parts", default=None,
                        help="run only these parts, comma-separated (the tables cover every "
                             "finished part)")
    args = parser.parse_args(argv)
    if args.top and args.quick:
        raise ValueError("--top and --quick exclude each other")
    return resolve_outputs(args)


def selected_parts(args):
    """(the parts tabulated, the names of those to run): --quick's, --top's or the
    study's parts, all tabulated where finished; those named by --parts run (all without
    it); ValueError (one line) naming an unknown part."""
    parts = QUICK_PARTS if args.quick else TOP_PARTS if args.top else PARTS
    if not args.parts:
        return parts, {part[0] for part in parts}
    known = [part[0] for part in parts]
    wanted = [name.strip() for name in args.parts.split(",") if name.strip()]
    unknown = ", ".join(name for name in wanted if name not in known)
    if unknown or not wanted:
        raise ValueError(f"--parts {args.parts!r}: " + (f"unknown part(s) {unknown}" if unknown
                         else "names no part") + f"; the parts here are {', '.join(known)}")
    return parts, set(wanted)


def resolve_outputs(args):
    """``args`` with ``runs``, ``data`` and ``figure`` filled in where not given: the
    study's places, or with ``--quick`` one folder of its own (:data:`QUICK_RUNS`).  A
    ValueError where ``--quick`` would write a table or the figure over one of the
    committed study's (:data:`COMMITTED`, in the repository or the working directory)."""
    top = getattr(args, "top", False)
    if args.runs is None:
        args.runs = QUICK_RUNS if args.quick else TOP_RUNS if top else "runs"
    if args.data is None:
        args.data = args.runs if args.quick else "data"
    if args.figure is None:
        args.figure = (os.path.join(args.runs, "paper_range.png") if args.quick
                       else os.path.join("docs", "figures",
                                         "paper_range_top.png" if top else "paper_range.png"))
    args.summary_file, args.stops_file = ((TOP_SUMMARY_FILE, TOP_STOPS_FILE) if top
                                          else (SUMMARY_FILE, STOPS_FILE))
    if args.quick:
        committed = {os.path.realpath(os.path.join(base, path))
                     for base in (ROOT, os.getcwd()) for path in COMMITTED}
        for path in (os.path.join(args.data, SUMMARY_FILE), os.path.join(args.data, STOPS_FILE),
                     args.figure):
            if path and os.path.realpath(path) in committed:
                raise ValueError(f"--quick would write over the committed study's {path!r}; "
                                 "leave --data and --figure out (they default to --runs) or "
                                 "give other places")
    return args


def cell_keys(frame):
    """The cells (g0, θ0) of a table or of a part's grid, as a set of rounded pairs (the
    values are the grid's own, :data:`G0`, :data:`THETA0`: rounding only spares them
    the last bit)."""
    return storage.study_keys(frame, ("g0", "theta0_deg"))


def expected_cells(args, parts, to_run):
    """The cells the tables will cover: those of the finished parts' stop tables, and
    (unless ``--read-only``) the grids of the unfinished parts that run."""
    cells = set()
    for name, g0, theta0 in parts:
        path = os.path.join(args.runs, name)
        if os.path.isfile(os.path.join(path, storage.STOPS_FILE)):
            cells |= cell_keys(storage.read_stop_table(path))
        elif not args.read_only and name in to_run:
            cells |= {(round(float(g), 9), round(float(t), 9)) for g in g0 for t in theta0}
    return cells


def committed_figure_table(args):
    """The committed summary table that the figure ``args.figure`` draws, where the
    figure is one of the study's committed figures (in the repository or the working
    directory), else None."""
    if not args.figure:
        return None
    for base in (ROOT, os.getcwd()):
        for figure, table in (("paper_range.png", SUMMARY_FILE),
                              ("paper_range_top.png", TOP_SUMMARY_FILE)):
            path = os.path.join(base, "docs", "figures", figure)
            if os.path.realpath(args.figure) == os.path.realpath(path):
                return os.path.join(base, "data", table)
    return None


def shrinking(args, cells):
    """The one-line refusal where writing tables and the figure of ``cells`` would shrink
    a table: one already at ``--data`` (the summary or the stops table), or the committed
    table the figure draws, holding cells that ``cells`` lacks; None where none would."""
    places = [(os.path.join(args.data, args.summary_file), "--data"),
              (os.path.join(args.data, args.stops_file), "--data"),
              (committed_figure_table(args), "--figure")]
    for path, option in places:
        if path is None:
            continue
        try:
            have, lost = storage.keys_a_write_would_drop(path, cells, ("g0", "theta0_deg"))
        except ValueError as exc:
            return f"{exc}: nothing written over it; give {option} another place"
        if lost:
            what = (f"{path!r}" if option == "--data"
                    else f"the figure {args.figure!r} (it draws {path!r})")
            parts = ("the finished parts" if args.read_only
                     else "the parts finished or to run")
            return (f"{parts} in {args.runs!r} cover {len(have) - len(lost)} of "
                    f"the {len(have)} cells of {what}: writing would drop {len(lost)} cells; "
                    "finish the other parts, or give --data and --figure other places (a "
                    "partial run never replaces a fuller table)")
    return None


def refuse_if_shrinking(args, cells):
    """Exit with status 2 and one line on stderr where :func:`shrinking` refuses."""
    refusal = shrinking(args, cells)
    if refusal is not None:
        print(f"paper_range_study: error: {refusal}", file=sys.stderr)
        sys.exit(2)


def steady_lines(table):
    """The printout's lines on the cells with seeds not steady at ``t_end`` (their tilt a
    snapshot), from a summary table; cells whose ``steady`` is unknown (``<NA>``: run with
    ``--no-early-stop``, no run tested) are counted apart, never as steady or moving."""
    known = table[table["steady"].notna()]
    moving = known[known["steady"] < known["seeds"]]
    lines = [f"cells with seeds not steady at t_end (their tilt a snapshot): {len(moving)}; "
             f"runs not steady: {int((known['seeds'] - known['steady']).sum())} of "
             f"{int(known['seeds'].sum())}"]
    lines += [f"  ({cell['g0']:.1f}, {cell['theta0_deg']:g}°): "
              f"{int(cell['seeds'] - cell['steady'])} of {int(cell['seeds'])}"
              for _, cell in moving.iterrows()]
    if len(known) < len(table):
        lines.append(f"cells whose steady state is unknown (run with --no-early-stop: no run "
                     f"tested): {len(table) - len(known)}")
    return lines


def main():
    try:
        args = parse_args()
        parts, to_run = selected_parts(args)
    except ValueError as exc:
        print(f"paper_range_study: error: {exc}", file=sys.stderr)
        sys.exit(2)
    expected = expected_cells(args, parts, to_run)
    if expected:  # (none: "no part has finished" below says it better)
        refuse_if_shrinking(args, expected)  # before any sweep runs
    frames, stops, checks = [], [], []
    for name, g0, theta0 in parts:
        path = os.path.join(args.runs, name)
        if not args.read_only and name in to_run:
            run_part(path, g0, theta0, args.threads, args.max_seeds, args.quick)
        if not os.path.isfile(os.path.join(path, storage.STOPS_FILE)):
            print(f"{name}: not finished, left out ({len(g0) * len(theta0)} cells)")
            continue
        frames.append(storage.read_seeds_auto(path).assign(part=name))
        stops.append(storage.read_stop_table(path).assign(part=name))
        check = os.path.join(path, storage.CHECK_DIR)
        if os.path.isdir(check):
            checks.append(storage.read_results(check))
    if not frames:  # --read-only before any part has finished
        sys.exit(f"paper_range_study: no part has finished in {args.runs!r} (no stop table "
                 "yet): nothing to tabulate")
    frame = pd.concat(frames, ignore_index=True)
    stop = pd.concat(stops, ignore_index=True).drop(columns="part")
    stop["n"] = stop["n"].astype("int64")
    check_rows = pd.concat(checks, ignore_index=True) if checks else pd.DataFrame()
    window = rest_window.stability_losses()  # where loops can rest: counted and drawn
    table = outcome_statistics.summarize(frame.drop(columns="part"), rest_window=window)
    refuse_if_shrinking(args, cell_keys(table) & cell_keys(stop))  # the cells as run
    os.makedirs(args.data, exist_ok=True)
    meta = dict(summary_of=" + ".join(sorted(set(frame["part"]))))
    shown = ["g0", "theta0_deg", "seeds", "determined", "p_stable", "p_in_plane", "p_3d",
             "tilt_median", "tilt_median_low", "tilt_median_high"]
    print_and_write(table, os.path.join(args.data, args.summary_file), meta,
                    shown, declarations=columns.SUMMARY_COLUMNS)
    print_and_write(stop, os.path.join(args.data, args.stops_file), meta,
                    ["g0", "theta0_deg", "seeds", "stop_reason", "runs", "check_verdict",
                     "check_tilt_wasserstein"], declarations=columns.STOP_COLUMNS)
    print_findings(table, frame.drop(columns="part"), check_rows)
    if args.figure:
        use_agg()
        save_distribution_figure(table, frame.drop(columns="part"), args.figure, dpi=FIGURE_DPI,
                                 rest_window=window)
        print(f"figure: {args.figure}")


def print_findings(table, frame, check_rows):
    """The printout: the cost, the certain and mixed cells, where seed 0 misleads, and
    the cells with seeds still moving at t_end."""
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
    print("\n".join(steady_lines(table)))


if __name__ == "__main__":
    main()
