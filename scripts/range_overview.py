"""The paper's range in one table and one figure: every cell of its grid, from the committed
study that answers it best (issue 53, item 4).

Usage: python scripts/range_overview.py [--data data] [--out data/paper_range_overview.parquet]
                                        [--figure docs/figures/paper_range_overview.png]
                                        [--survival-figure PATH] [--window-n 16]

Runs nothing: it reads the committed tables and sweeps under ``--data``, in this order of
precedence:

* Run to rest (``t_max`` 40): the sweeps under ``DATA/rest_runs`` (``scripts/rest_study.py``:
  the four 16-seed cells of the study, and the ``range_rest_t<θ0>`` sweeps, 8 seeds per
  cell), each cell once all its seeds have finished (a sweep still running gives the
  cells it has finished), summarised by ``loopsim.summarize`` with the stable branch's
  window.  A cell in several sweeps takes the one with the most seeds.
* At the paper's horizon (``t_max`` 10): ``DATA/paper_range_top_summary.parquet`` and
  ``DATA/paper_range_summary.parquet`` (``scripts/paper_range_study.py``, ``--seeds auto``
  with twins).
* At the paper's horizon, unfinished: the ``--seeds auto`` parts under
  ``DATA/paper_range_runs`` that have not finished, each cell with the rounds it has
  finished (a round's fast seeds finish first, so a round counts only whole).
* A cell in none of them is a row with ``seeds`` 0 and an empty ``source``.

P(not at rest by t = 10) is over the runs that did not fail: 1 - ``p_rest_t10`` where the
source has it, else 1 - steady / (seeds - failed) with its Wilson interval (the steady
test is what "at rest" means).

Writes ``--out`` (columns: ``loopsim.columns.RANGE_OVERVIEW_COLUMNS``, each described;
225 rows, one per cell), ``--figure`` (``loopsim.figures.range_overview``: the regime
probabilities and P(not at rest by t = 10) per cell, the thresholds and the stable
branch's upper edge) and ``--survival-figure`` (``loopsim.figures.pooled_survival``:
every loop of the cells run to rest, the samples the table takes, pooled into one
Kaplan–Meier survival for the 3D loops and one for the others, each with its exponential
tail after t = 10).  It refuses (exit status 2, nothing written) where ``--out`` holds
another kind of table, or an overview that knows a cell this run would not.
"""
import argparse
import glob
import json
import os
import sys

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

import loopsim
from loopsim import columns, outcome_statistics, storage, validation
from loopsim.intervals import wilson_interval
from loopsim.stability import rest_window
from loopsim.survival import PAPER_HORIZON

#: The paper's grid: g0 = 10..350 in 15 values, θ0 = 6..90° in 15.
G0 = np.linspace(10.0, 350.0, 15)
THETA0 = np.linspace(6.0, 90.0, 15)
#: The pooled survival figure's name, beside ``--figure`` unless given.
SURVIVAL_FIGURE = "range_survival.png"
#: The t = 10 tables, the first that holds a cell answering it.
HORIZON_TABLES = ("paper_range_top_summary.parquet", "paper_range_summary.parquet")
CELL = ("g0", "theta0_deg")


def cell_key(g0, theta0):
    """A cell's key, robust to the last bits of g0 (np.linspace against its repr)."""
    return round(float(g0), 6), round(float(theta0), 6)


def finished_cells(path):
    """{cell key: rows} of the cells of the sweep at ``path`` whose every case has finished
    (``outcome_statistics.complete_cells``); none for a folder that is not (yet) a sweep
    or a sweep with no finished case."""
    try:
        frame = loopsim.read_results(path)
        return outcome_statistics.complete_cells(frame) if len(frame) else {}
    except (FileNotFoundError, ValueError) as exc:
        print(f"{path}: left out ({exc})", file=sys.stderr)
        return {}


def summarised(cells, window):
    """{cell key: (source, t_max, summary row)} from {cell key: (source, rows)}."""
    return {key: (source, float(rows["t_end"].max()),
                  outcome_statistics.summarize(rows, rest_window=window).iloc[0])
            for key, (source, rows) in cells.items()}


def rest_samples(data):
    """{cell key: (source, rows)} of the cells run to rest, the largest sample of each."""
    best = {}
    for path in sorted(glob.glob(os.path.join(data, "rest_runs", "*rest_t*"))):
        if not os.path.isdir(path):
            continue
        for key, rows in finished_cells(path).items():
            if key not in best or len(rows) > len(best[key][1]):
                best[key] = (os.path.relpath(path, os.path.dirname(data)), rows)
    return best


def horizon_cells(data):
    """The cells of the t = 10 tables (the first table wins)."""
    out = {}
    for name in HORIZON_TABLES:
        path = os.path.join(data, name)
        if not os.path.exists(path):
            continue
        for _, row in pd.read_parquet(path).iterrows():
            out.setdefault(cell_key(row["g0"], row["theta0_deg"]),
                           (os.path.join(os.path.basename(data), name), PAPER_HORIZON, row))
    return out


def unfinished_part_cells(data, window):
    """The cells of the unfinished ``--seeds auto`` parts under ``DATA/paper_range_runs``
    (no stop table yet), each with its rounds up to the first it has not finished."""
    found = {}
    for part in sorted(glob.glob(os.path.join(data, "paper_range_runs", "*"))):
        if os.path.isfile(os.path.join(part, storage.STOPS_FILE)):
            continue   # finished: in the t = 10 tables
        source = os.path.relpath(part, os.path.dirname(data)) + " (unfinished)"
        cells, growing = {}, set()
        for number, path in enumerate(sorted(glob.glob(os.path.join(part, "round-*")))):
            done = finished_cells(path)
            if number == 0:
                cells, growing = dict(done), set(done)
                continue
            for key in sorted(growing):
                if key in done:
                    cells[key] = pd.concat([cells[key], done[key]], ignore_index=True)
                else:   # not in this round, or not finished in it: no later round counts
                    growing.discard(key)
        found.update({key: (source, rows) for key, rows in cells.items()})
    return summarised(found, window)


def overview_row(row, source, t_max):
    """One cell's row of the overview from a ``loopsim.summarize`` row."""
    out = {name: row.get(name, np.nan) for name in columns.RANGE_OVERVIEW_COLUMNS}
    seeds = int(row["seeds"])
    out.update(source=source, t_max=t_max, seeds=seeds,
               q0=row["g0"] * np.sin(np.radians(row["theta0_deg"])) / 3)
    if "p_rest_t10" in row and row["p_rest_t10"] == row["p_rest_t10"]:
        out["p_not_rest_t10"] = 1.0 - row["p_rest_t10"]
        out["p_not_rest_t10_low"] = 1.0 - row["p_rest_t10_high"]
        out["p_not_rest_t10_high"] = 1.0 - row["p_rest_t10_low"]
        out["at_rest"] = row["at_rest"]
    elif pd.notna(row.get("steady")):   # a t = 10 table without the settling statistics
        observed = seeds - int(round(row["p_failed"] * seeds))
        moving = observed - int(row["steady"])
        if observed:
            out["p_not_rest_t10"] = moving / observed
            out["p_not_rest_t10_low"], out["p_not_rest_t10_high"] = wilson_interval(moving,
                                                                                    observed)
        out["at_rest"] = row["steady"]
    return out


def overview(data, window, rested):
    """The 225-row table: each cell from the run-to-rest samples ``rested``
    (:func:`rest_samples`), else the t = 10 tables, else the unfinished t = 10 parts,
    else empty."""
    found = {**unfinished_part_cells(data, window), **horizon_cells(data),
             **summarised(rested, window)}   # later sources win
    rows = []
    for theta0 in THETA0:
        for g0 in G0:
            key = cell_key(g0, theta0)
            row = overview_row(found[key][2], *found[key][:2]) if key in found else None
            if row is None:
                row = {name: np.nan for name in columns.RANGE_OVERVIEW_COLUMNS}
                row.update(g0=g0, theta0_deg=theta0, q0=g0 * np.sin(np.radians(theta0)) / 3,
                           source="", seeds=0)
            rows.append(row)
    table = pd.DataFrame(rows, columns=list(columns.RANGE_OVERVIEW_COLUMNS))
    for name in ("seeds", "at_rest", "rest_inside", "rest_below", "rest_outside"):
        table[name] = table[name].astype("Int64")   # unknown: <NA>
    return table


def known_cells(path):
    """The cells (``storage.study_keys``) with seeds of the overview table at ``path``;
    none where there is no file.  ValueError (one line) where it cannot be read."""
    if not os.path.isfile(path):
        return set()
    try:
        if b"loopsim_range_overview" not in (pq.read_schema(path).metadata or {}):
            raise ValueError("it is not a range overview")
        held = pd.read_parquet(path, columns=[*CELL, "seeds"])
    except Exception as exc:  # noqa: BLE001 - any unreadable table is kept as it is
        raise ValueError(f"{path!r} cannot be read to compare its rows ({exc}): nothing "
                         "written over it; give another --out") from None
    return storage.study_keys(held[held["seeds"] > 0], CELL)


def tabulate(args):
    """(the overview table, the window, its metadata), or a one-line ValueError: an output
    that cannot be written, nothing to tabulate under ``--data``, a bad ``--window-n``, or
    a table at ``--out`` that knows a cell this run would not (it is kept as it is)."""
    args.data = os.path.normpath(args.data)   # "data/" names its sources as "data" does
    validation.check_output_file("--out", args.out)
    validation.check_output_file("--figure", args.figure)
    validation.check_output_file("--survival-figure", args.survival_figure)
    if not any(os.path.exists(os.path.join(args.data, name))
               for name in (*HORIZON_TABLES, "rest_runs")):
        raise ValueError(f"no committed table or rest_runs folder under --data {args.data!r}")
    window = rest_window.stability_losses(args.window_n)
    rested = rest_samples(args.data)
    table = overview(args.data, window, rested)
    known = table[table["seeds"] > 0]
    held = known_cells(args.out)
    lost = held - storage.study_keys(known, CELL)
    if lost:
        g0, theta0 = sorted(lost)[0]
        raise ValueError(f"{args.out} knows {len(held)} cells, this run only {len(known)} "
                         f"(e.g. g0 = {g0:g}, theta0 = {theta0:g}): nothing written over it; "
                         "give another --out")
    meta = dict(sources=sorted(set(known["source"])), window=window.as_dict(),
                intervals="95% Wilson or Kaplan-Meier log-log", loopsim_version=loopsim.__version__)
    pooled = pd.concat([rows for _, rows in rested.values()], ignore_index=True) \
        if rested else None
    return table, window, meta, pooled


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", default="data", help="the committed tables and sweeps")
    parser.add_argument("--out", default=os.path.join("data", "paper_range_overview.parquet"))
    parser.add_argument("--figure",
                        default=os.path.join("docs", "figures", "paper_range_overview.png"))
    parser.add_argument("--window-n", type=int, default=rest_window.DEFAULT_WINDOW_N,
                        help="truncation order of the steady branch whose window is used")
    parser.add_argument("--survival-figure", default=None,
                        help="the pooled survival of every loop run to rest (default: "
                        "range_survival.png beside --figure)")
    args = parser.parse_args(argv)
    if args.survival_figure is None:
        args.survival_figure = os.path.join(os.path.dirname(args.figure), SURVIVAL_FIGURE)
    try:
        table, window, meta, pooled = tabulate(args)
    except ValueError as exc:
        print(f"range_overview: error: {exc}", file=sys.stderr)
        sys.exit(2)
    import matplotlib

    matplotlib.use("Agg")
    from loopsim import figures

    figure = figures.range_overview(table, window)   # drawn before anything is written
    survival = None if pooled is None else figures.pooled_survival(pooled, groups={
        "3D loops": pooled["regime"].eq("3d"),
        "stable or in-plane": pooled["regime"].isin(("stable", "in-plane"))})
    arrow = pa.Table.from_pandas(table, preserve_index=False)
    arrow = arrow.replace_schema_metadata(storage.provenance(
        loopsim_range_overview=json.dumps(meta)))
    storage.write_table_atomically(storage.described(arrow, columns.RANGE_OVERVIEW_COLUMNS),
                                   args.out)
    figures.save(figure, args.figure, dpi=150)
    if survival is not None:
        figures.save(survival, args.survival_figure)
    known = table[table["seeds"] > 0]
    by_source = known.groupby("t_max").size()
    print(f"wrote {args.out}: {len(known)} of {len(table)} cells known "
          + ", ".join(f"{n} at t_max = {t:g}" for t, n in by_source.items())
          + f"; figures {args.figure}"
          + (f", {args.survival_figure}" if survival is not None else ""))


if __name__ == "__main__":
    main()
