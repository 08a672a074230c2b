"""Is t = 10 enough? Loops at the top of the paper's range run to rest (issue 53, item 3).

Usage: python scripts/rest_study.py [--runs data/rest_runs] [--threads T]
                                    [--loopsim loopsim] [--out data/rest_study.parquet]
                                    [--figures docs/figures] [--read-only]

Per cell, 16 seeds (0-15) with the defaults (``--n auto``, radau5 or rkf45 as chosen,
rtol 1e-6, atol 1e-9, the early stop on), no twins, and ``--t-end 40``: each loop runs
until it passes the steady test (its settling time is then ``t_final``) or reaches
t = 40, where it is censored (``loopsim.survival``).  The cells: (350, 18°) and
(325.7, 18°), whose loops tumble at t = 10 in 2-6 of 16 seeds, and two cells of the
paper's range never run before, (350, 24°) (q0 = 47.4) and (252.9, 60°) (q0 = 73.0),
both above the stable branch's window (q0 > 37.55: their loops must turn their plane
before they can rest).

Per cell the table holds: the settling statistics (Kaplan–Meier survival of "not yet at
rest", P(at rest by t = 10), the median settling time, the time by which 95 % rest, the
escape rate after t = 10, how many still move at t = 40), the stable branch's tilt
window at the cell's g0 (``loopsim.stability.rest_window``, n = 16) and where the loops
at rest lie in it, the regime shares and tilt quartiles at rest, and, where a t = 10
sample of the same cell exists (the convergence study's ``jmid`` sweeps, 16 seeds at
the defaults, code c5f1a71, whose loopsim/ computes as b1d79af's), the differences of
P(in-plane), P(3D) and the tilt quartiles at rest minus at t = 10 (all its rows: what a
t = 10 table reports), with 95 % intervals,
the smallest difference each could detect and a verdict
(``loopsim.distribution_differences``).  Those are two independent samples: the
horizon changes where the integrator samples the late window, and from there on a
chaotic trajectory is another sample, so the t = 40 runs are not continuations of the
t = 10 ones.

Each cell is one ``loopsim sweep``, run by the ``--loopsim`` executable (a frozen
install keeps the study on one version of the code; the code each ran on is in
``STUDY_COMMITS.json`` beside the sweeps), resumable; ``--read-only`` tabulates what has
finished (a sweep with fewer than 16 rows is left out).  The paper's empty cells above
g0 = 250, run to rest with 8 seeds in one sweep per tilt (``range_rest_t<θ0>``, queued
apart: docs/studies/rest.md), are summarised into ``--range-out`` as they finish.  A
table never shrinks: the script refuses to overwrite a table with one that lacks a cell
it holds.  It writes
the table (columns: ``loopsim.columns.REST_STUDY_COLUMNS``) and two figures:
``rest_survival.png`` (the survival curves) and ``rest_tilts.png`` (tilts at rest over
the window).
"""
import argparse
import json
import os
import shutil
import subprocess
import sys

import numpy as np
import pandas as pd
import pyarrow as pa

import loopsim
from loopsim import columns, outcome_statistics, storage, validation
from loopsim import distribution_differences as dd
from loopsim.stability import rest_window

G0 = np.linspace(10.0, 350.0, 15)  # the paper's grid
SEEDS = 16
T_MAX = 40.0
OPTIONS = ["--n", "auto", "--no-twin", "--t-end", repr(T_MAX), "--chunk-size", "1"]
#: (sweep name, g0, θ0, the t = 10 sample of the same cell or None), in the order they run.
SWEEPS = (
    ("rest_t18_350", G0[14], 18.0, os.path.join("data", "convergence_runs", "jmid_t18")),
    ("rest_t18_326", G0[13], 18.0, os.path.join("data", "convergence_runs", "jmid_t18_326")),
    ("rest_t24_350", G0[14], 24.0, None),
    ("rest_t60_253", G0[10], 60.0, None),
)
REGIMES = ("stable", "in-plane", "3d")
ENSEMBLE = ("loopsim's seeded perturbation (loopsim.shapes.circle): seeds 0-15, RMS size 1e-3 "
            "in modes 2-6 (zero-padded as n climbs), amplitudes N(0,1)/k^2")


def sweep_command(loopsim_exe, runs, name, g0, theta0, threads):
    return [loopsim_exe, "sweep", "--g0", repr(float(g0)), "--theta0", repr(float(theta0)),
            "--seeds", str(SEEDS), *OPTIONS, "--threads", str(threads),
            "--out", os.path.join(runs, name), "--progress-every", "300"]


def indicators(frame):
    """The rows with is_<regime> columns (the comparison's probabilities)."""
    return frame.assign(**{f"is_{r.replace('-', '_')}": frame["regime"].eq(r) for r in REGIMES})


def cell_row(name, rows, base, window):
    """One row of the table: the cell's settling statistics over all its runs, its
    window, the regime shares and tilt quartiles over the loops that came to rest, and,
    with a t = 10 sample ``base``, the differences at rest minus at t = 10."""
    g0, theta0 = float(rows["g0"].iloc[0]), float(rows["theta0_deg"].iloc[0])
    stats = outcome_statistics.summarize(rows, rest_window=window).iloc[0]
    rested = rows[rows["stop_reason"].eq("steady")]
    at_rest = outcome_statistics.summarize(rested).iloc[0] if len(rested) else None
    low, high = window.tilts(g0)
    moving = int(stats["rest_observed"] - stats["at_rest"])
    out = dict(g0=g0, theta0_deg=theta0, q0=g0 * np.sin(np.radians(theta0)) / 3, sweep=name,
               t_max=float(rows["t_end"].max()), window_low_deg=low, window_high_deg=high,
               seeds=len(rows), failed=int(rows["regime"].eq("failed").sum()),
               moving_at_t_max=moving)
    for key in ("rest_observed", "at_rest", "rest_inside", "rest_below", "rest_outside",
                "p_rest_t10", "p_rest_t10_low", "p_rest_t10_high", "t_rest_median",
                "t_rest_median_low", "t_rest_median_high", "t_rest_q95", "escape_events",
                "tail_time", "escape_rate", "escape_rate_low", "escape_rate_high"):
        out[key] = stats[key]
    for key in ("rest_observed", "at_rest", "rest_inside", "rest_below", "rest_outside",
                "escape_events"):
        out[key] = int(out[key])
    for key in ("p_stable", "p_in_plane", "p_3d", "tilt_q25", "tilt_median", "tilt_q75",
                "tilt_median_low", "tilt_median_high"):
        out[key] = at_rest[key] if at_rest is not None else np.nan
    out["nfev_mean"] = float(rows["nfev"].mean())
    out["wall_s"] = float(rows["wall_s"].sum())
    if base is not None and len(rested):
        out["baseline"] = base.attrs["name"]
        out["base_seeds"] = len(base)
        out["base_p_steady"] = float(base["stop_reason"].eq("steady").mean())
        out["base_p_3d"] = float(base["regime"].eq("3d").mean())
        out["base_tilt_median"] = float(np.nanmedian(base["theta_final_deg"]))
        compared = dd.compare_samples(indicators(base), indicators(rested),
                                      ["is_in_plane", "is_3d"])
        out.update({k: v for k, v in compared.items()
                    if k.startswith("delta_") or k == "verdict"})
        out["verdict"] = out["verdict"].split(" ")[0]
    return out


def tabulate(frames, bases, window):
    table = [cell_row(name, rows, bases.get(name), window) for name, rows in frames.items()]
    return pd.DataFrame(table).sort_values(["theta0_deg", "g0"], ignore_index=True)


#: The paper's cells above g0 = 250, run to rest: one sweep per tilt, 8 seeds each
#: (``data/rest_runs/range_rest_t<theta0>``), tabulated into :data:`RANGE_OUT` once it
#: has finished: the empty cells at 24-90° first, then those at 6-18°, whose t = 10
#: answer has no settling times (at 18° and 24° without the cells the 16-seed sweeps
#: above already ran).
RANGE_THETA0 = tuple(range(6, 91, 6))
RANGE_SEEDS = 8
RANGE_OUT = os.path.join("data", "paper_range_rest_summary.parquet")


def range_rows(runs):
    """The rows of every finished range sweep in ``runs``, concatenated, or None where
    none has finished."""
    frames = []
    for theta0 in RANGE_THETA0:
        path = os.path.join(runs, f"range_rest_t{theta0}")
        try:
            frame = loopsim.read_results(path)
        except (FileNotFoundError, ValueError):
            continue
        cases = len(storage.read_sweep_file(path)["config"]["cases"])
        if len(frame) < cases:
            print(f"range_rest_t{theta0}: {len(frame)} of {cases} cases, left out")
            continue
        frames.append(frame)
    return pd.concat(frames, ignore_index=True) if frames else None


def write_range(table, out):
    """Write the range sweeps' summary to ``out`` (``SUMMARY_COLUMNS``)."""
    arrow = pa.Table.from_pandas(table, preserve_index=False)
    arrow = arrow.replace_schema_metadata(storage.provenance(loopsim_summary=json.dumps(
        dict(table.attrs["loopsim_summary"], summary_of="data/rest_runs/range_rest_t*",
             ensemble=ENSEMBLE.replace("0-15", f"0-{RANGE_SEEDS - 1}")))))
    storage.write_table_atomically(storage.described(arrow, columns.SUMMARY_COLUMNS), out)
    print(f"wrote {out}: {len(table)} cells")


def refuse_to_shrink(table, out, option):
    """Exit 2 if the table at ``out`` (the path given as ``option``) holds a cell that
    ``table`` lacks (a partial run would shrink a committed table), or cannot be read."""
    cells = ("g0", "theta0_deg")
    try:
        held, lost = storage.keys_a_write_would_drop(out, storage.study_keys(table, cells), cells)
    except ValueError as exc:
        print(f"rest_study: error: {exc}: nothing written over it; give another {option}",
              file=sys.stderr)
        sys.exit(2)
    if lost:
        g0, theta0 = sorted(lost)[0]
        print(f"rest_study: error: {out} holds {len(held)} cells, this run only {len(table)} "
              f"(e.g. g0 = {g0:g}, theta0 = {theta0:g} is missing); nothing written; give "
              f"another {option}", file=sys.stderr)
        sys.exit(2)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", default=os.path.join("data", "rest_runs"))
    parser.add_argument("--threads", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--loopsim", default="loopsim", help="the loopsim executable that runs "
                        "the sweeps (a frozen install keeps the study on one code version)")
    parser.add_argument("--out", default=os.path.join("data", "rest_study.parquet"))
    parser.add_argument("--figures", default=os.path.join("docs", "figures"),
                        help="directory of rest_survival.png and rest_tilts.png")
    parser.add_argument("--read-only", action="store_true",
                        help="run nothing: tabulate the sweeps that have finished")
    parser.add_argument("--range-out", default=RANGE_OUT,
                        help="the summary of the paper's empty cells run to rest (the finished "
                             "range_rest_t* sweeps in --runs)")
    parser.add_argument("--window-n", type=int, default=rest_window.DEFAULT_WINDOW_N,
                        help="truncation order of the steady branch whose window is used")
    args = parser.parse_args()
    if not args.read_only and shutil.which(args.loopsim) is None:
        sys.exit(f"rest_study: error: no loopsim executable at {args.loopsim!r}")
    try:   # every output and the window's order, before any work
        validation.check_output_file("--out", args.out)
        validation.check_output_file("--range-out", args.range_out)
        validation.check_output_directory("--figures", args.figures)
        if os.path.realpath(args.out) == os.path.realpath(args.range_out):
            raise ValueError(f"--out and --range-out are one file, {args.out!r}")
        validation.check_count("--window-n", args.window_n, 4, validation.MAX_BRANCH_N,
                               "the continuation's cost grows like n^3 per point")
    except ValueError as exc:
        print(f"rest_study: error: {exc}", file=sys.stderr)
        sys.exit(2)
    frames, bases = {}, {}
    for name, g0, theta0, base in SWEEPS:
        path = os.path.join(args.runs, name)
        if not args.read_only:
            command = sweep_command(args.loopsim, args.runs, name, g0, theta0, args.threads)
            print("$ " + " ".join(command), flush=True)
            if subprocess.call(command) not in (0, 1):
                sys.exit(f"rest_study: the sweep into {path} did not finish")
        try:
            frame = loopsim.read_results(path)
        except (FileNotFoundError, ValueError):
            print(f"{name}: not started, left out")
            continue
        if len(frame) < SEEDS:
            print(f"{name}: {len(frame)} of {SEEDS} cases, left out")
            continue
        frames[name] = frame
        if base is not None:
            bases[name] = loopsim.read_results(base)
            bases[name].attrs["name"] = os.path.basename(base)
    if not frames:
        sys.exit("rest_study: no sweep has finished")
    window = rest_window.stability_losses(args.window_n)
    table = tabulate(frames, bases, window)
    ranged = range_rows(args.runs)
    range_table = (None if ranged is None
                   else outcome_statistics.summarize(ranged, rest_window=window))
    refuse_to_shrink(table, args.out, "--out")   # both checked before anything is written
    if range_table is not None:
        refuse_to_shrink(range_table, args.range_out, "--range-out")
    meta = dict(ensemble=ENSEMBLE, seeds=f"0-{SEEDS - 1}", sweeps=list(frames),
                options=" ".join(OPTIONS), t_max=T_MAX,
                window=window.as_dict(), intervals="95% Wilson or Kaplan-Meier log-log (P), "
                "Brookmeyer-Crowley (median), exact Poisson (escape rate), Newcombe hybrid "
                "score (P differences), percentile bootstrap (quantiles)",
                power_of_detectable=dd.POWER, loopsim_version=loopsim.__version__)
    arrow = pa.Table.from_pandas(table, preserve_index=False)
    arrow = arrow.replace_schema_metadata(storage.provenance(loopsim_rest_study=json.dumps(meta)))
    storage.write_table_atomically(storage.described(arrow, columns.REST_STUDY_COLUMNS), args.out)
    import matplotlib

    matplotlib.use("Agg")
    from loopsim import figures

    rows = pd.concat(frames.values(), ignore_index=True)
    figures.save(figures.survival_curves(rows), os.path.join(args.figures, "rest_survival.png"))
    figures.save(figures.rest_tilts(rows, window), os.path.join(args.figures, "rest_tilts.png"))
    if range_table is not None:
        write_range(range_table, args.range_out)
    with pd.option_context("display.width", 220, "display.max_columns", 40):
        shown = ["g0", "theta0_deg", "q0", "seeds", "at_rest", "moving_at_t_max",
                 "p_rest_t10", "t_rest_median", "t_rest_q95", "rest_inside", "rest_below",
                 "rest_outside"] + [c for c in ("verdict",) if c in table]
        print(table[shown].to_string())
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
