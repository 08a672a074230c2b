"""Convergence in distribution at the top of the paper's range
(docs/studies/convergence-top.md).

Usage: python scripts/convergence_study.py [--runs runs/convergence] [--threads T]
                                           [--loopsim loopsim] [--out data/convergence_top.parquet]
                                           [--read-only]

Per cell, 16 seeds (0-15) at each of its settings, all without twins (a cell there is
a distribution, not an outcome):

* ``default``:  ``--n auto`` (radau5, rtol 1e-6, atol 1e-9, n up to 32);
* ``rtol1e-8``: the same at ``--rtol 1e-8 --atol 1e-11``;
* ``n40``:      ``--n 40 --method radau5`` (rtol 1e-6);
* ``amp1e-4``:  ``--n auto --perturbation 1e-4`` (three cells);
* ``jmid``:     the defaults on the code whose radau5 takes its Jacobian inside the step
  (29b7d79), at the 18° cells: at (350, 18°) compared with ``default`` (fb48539), across
  the two codes: the same answer in distribution at a lower cost per sample?
* ``jmid_rtol1e-8``, ``jmid_n40``: ``rtol1e-8`` and ``n40`` on that code (cd63406, whose
  loopsim/ differs from 29b7d79 only in a column's description), at the 18° cells,
  compared with ``jmid``, the defaults on the same code.
* ``jmid_rtol1e-3``: ``--rtol 1e-3 --atol 1e-6`` on that code (c5f1a71, loopsim/ as
  cd63406 but for column descriptions), at the 18° cells, compared with ``jmid``: is the
  answer at a chaotic cell, where only the end state's distribution means anything, the
  same at a thousand times the tolerance, and at what cost per sample?

The ensemble is loopsim's seeded perturbation (``loopsim.shapes.circle``): RMS size 1e-3
(1e-4 for ``amp1e-4``) in modes 2 to the starting order with amplitudes drawn as N(0, 1)/k²,
the loop rescaled to length 2π; the starting order is 6 with ``--n auto`` (modes 2-6,
zero-padded when the ladder climbs) and 40 with ``--n 40`` (modes 7-40 then carry 1.7 %
of the perturbation's variance).

Each setting is one ``loopsim sweep`` per group of cells, run by the ``--loopsim``
executable (a frozen install keeps a study on one version of the code: the sweeps record
their configuration, not the code), in the order below, each resumable; ``--read-only``
tabulates the sweeps that have finished.  The code each sweep ran on is in
``STUDY_COMMITS.json`` beside them: the 12° and 60° cells on one commit, the 18° cells
(which alone record ``terminal_state``, ``loopsim.late_motion``) on later ones.  The
table (one row per cell and setting; columns in loopsim.columns.CONVERGENCE_COLUMNS)
compares every setting with its baseline (BASELINE: the defaults on the same code, but
``jmid`` with ``default``, across codes) through
``loopsim.distribution_differences``: differences of the regime probabilities, of
P(steady before t_end) and of the tilt quartiles, with 95 % intervals, the smallest
difference each comparison could have detected, and a verdict.

Before any sweep runs, ``--out`` must be a file that can be written (not a directory; its
folder writable or makeable) and, unless ``--read-only``, ``--loopsim`` an executable:
otherwise one line and exit status 2.  A partial run never shrinks the table: where the
finished sweeps would give fewer rows (cell and setting) than the table already at
``--out`` (the committed ``data/convergence_top.parquet``, say, from a ``--runs`` folder
holding some of the sweeps), the script refuses in one line, naming the rows it would
lose, with exit status 2 and nothing written; give ``--out`` another place to tabulate
a partial run.  It does not merge: the rows would come from different runs.
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
from loopsim import distribution_differences as dd
from loopsim import columns, outcome_statistics, storage

G0 = np.linspace(10.0, 350.0, 15)  # the paper's grid
G12 = ",".join(repr(float(v)) for v in G0[10:])  # 252.9 ... 350
SEEDS = 16
SETTINGS = {
    "default": ["--n", "auto"],
    "rtol1e-8": ["--n", "auto", "--rtol", "1e-8", "--atol", "1e-11"],
    "n40": ["--n", "40", "--method", "radau5"],
    "amp1e-4": ["--n", "auto", "--perturbation", "1e-4"],
    "jmid": ["--n", "auto"],  # the defaults, on the code with radau5's Jacobian inside the step
    "jmid_rtol1e-8": ["--n", "auto", "--rtol", "1e-8", "--atol", "1e-11"],
    "jmid_n40": ["--n", "40", "--method", "radau5"],
    "jmid_rtol1e-3": ["--n", "auto", "--rtol", "1e-3", "--atol", "1e-6"],
}
#: the setting each one is compared with (``default`` where not named): the defaults on
#: the same code, except ``jmid`` itself, compared with ``default`` across two codes
BASELINE = {"jmid_rtol1e-8": "jmid", "jmid_n40": "jmid", "jmid_rtol1e-3": "jmid"}
#: (sweep name, setting, g0 values, θ0) in the order they run.
SWEEPS = (
    ("default_t12", "default", G12, "12"),
    ("default_t60", "default", repr(float(G0[9])), "60"),
    ("rtol1e-8_t12", "rtol1e-8", G12, "12"),
    ("rtol1e-8_t60", "rtol1e-8", repr(float(G0[9])), "60"),
    ("amp1e-4_t12", "amp1e-4", f"{G0[12]!r},{G0[14]!r}", "12"),
    ("amp1e-4_t60", "amp1e-4", repr(float(G0[9])), "60"),
    ("n40_t12", "n40", G12, "12"),
    ("n40_t60", "n40", repr(float(G0[9])), "60"),
    ("default_t18", "default", f"{G0[14]!r},{G0[13]!r}", "18"),
    ("jmid_t18", "jmid", repr(float(G0[14])), "18"),
    ("jmid_rtol1e-8_t18", "jmid_rtol1e-8", repr(float(G0[14])), "18"),
    ("jmid_n40_t18", "jmid_n40", repr(float(G0[14])), "18"),
    ("jmid_t18_326", "jmid", repr(float(G0[13])), "18"),
    ("jmid_rtol1e-8_t18_326", "jmid_rtol1e-8", repr(float(G0[13])), "18"),
    ("jmid_n40_t18_326", "jmid_n40", repr(float(G0[13])), "18"),
    ("jmid_rtol1e-3_t18", "jmid_rtol1e-3", repr(float(G0[14])), "18"),
    ("jmid_rtol1e-3_t18_326", "jmid_rtol1e-3", repr(float(G0[13])), "18"),
)
ENSEMBLE = ("loopsim's seeded perturbation (loopsim.shapes.circle): seeds 0-15, RMS size "
            "1e-3 (1e-4 for amp1e-4) in modes 2 to the starting order (6 with --n auto, "
            "zero-padded as n climbs; 40 with --n 40), amplitudes N(0,1)/k^2")
REGIMES = ("stable", "in-plane", "3d")


def sweep_command(loopsim_exe, runs, name, setting, g0, theta0, threads):
    return [loopsim_exe, "sweep", "--g0", g0, "--theta0", theta0, "--seeds", str(SEEDS),
            "--no-twin", *SETTINGS[setting], "--threads", str(threads),
            "--out", os.path.join(runs, name), "--progress-every", "120"]


def cell_rows(frame):
    """Per-row outcome indicators: is_<regime> and steady (empty where untested)."""
    out = frame.assign(**{f"is_{r.replace('-', '_')}": frame["regime"].eq(r) for r in REGIMES})
    out["steady"] = frame["stop_reason"].eq("steady").astype("boolean")
    out.loc[frame["stop_reason"].isna(), "steady"] = pd.NA
    if "early_stop" in frame:  # a run never tested for a steady state: unknown
        out.loc[frame["early_stop"].eq(False).fillna(False).astype(bool), "steady"] = pd.NA
    out["unsteady"] = frame["terminal_state"].eq("unsteady").astype("boolean")
    out.loc[frame["terminal_state"].isna(), "unsteady"] = pd.NA  # written before it existed
    return out


def describe(rows):
    """Per-cell statistics of one setting."""
    out = dict(seeds=len(rows), failed=int(rows["regime"].eq("failed").sum()))
    for name in [f"is_{r.replace('-', '_')}" for r in REGIMES] + ["steady", "unsteady"]:
        values = rows[name].dropna().astype(bool)
        if not len(values):  # not recorded (unsteady: sweeps on the older code)
            out[f"p_{name}"] = out[f"p_{name}_low"] = out[f"p_{name}_high"] = np.nan
            continue
        hits = int(values.sum())
        out[f"p_{name[3:] if name.startswith('is_') else name}"] = hits / max(len(values), 1)
        low, high = outcome_statistics.wilson_interval(hits, len(values))
        key = name[3:] if name.startswith("is_") else name
        out[f"p_{key}_low"], out[f"p_{key}_high"] = low, high
    certain = [r for r in REGIMES if dd.certain(int(rows["regime"].eq(r).sum()), len(rows))]
    out["certain_regime"] = certain[0] if certain else None
    tilt = rows["theta_final_deg"].to_numpy(float)
    out["tilt_q25"], out["tilt_q50"], out["tilt_q75"] = np.nanpercentile(tilt, [25, 50, 75])
    out["tilt_q50_low"], out["tilt_q50_high"] = outcome_statistics.bootstrap_interval(tilt)
    out["nfev_mean"] = float(rows["nfev"].mean())
    out["wall_s"] = float(rows["wall_s"].sum())
    return out


def tabulate(frames):
    """One row per cell and setting; the comparisons with each setting's baseline."""
    table = []
    for setting, frame in frames.items():
        name = BASELINE.get(setting, "default")
        for (g0, theta0), rows in frame.groupby(["g0", "theta0_deg"]):
            row = dict(g0=g0, theta0_deg=theta0, q0=g0 * np.sin(np.radians(theta0)) / 3,
                       setting=setting, baseline=None, **describe(rows))
            default = frames.get(name)
            if setting != "default" and default is not None:
                base = default[(default["g0"] == g0) & (default["theta0_deg"] == theta0)]
                if len(base):
                    row["baseline"] = name
                    recorded = base["unsteady"].notna().any() and rows["unsteady"].notna().any()
                    row.update(dd.compare_samples(base, rows, ["is_in_plane", "is_3d", "steady"]
                                                  + (["unsteady"] if recorded else [])))
                    row["verdict"] = row["verdict"].split(" ")[0]
            table.append(row)
    return pd.DataFrame(table).sort_values(["theta0_deg", "g0", "setting"], ignore_index=True)


def fail(message):
    """One line on stderr and exit status 2 (bad input: nothing was run or written)."""
    print(f"convergence_study: error: {message}", file=sys.stderr)
    sys.exit(2)


def check_places(args):
    """One-line refusals of an ``--out`` that cannot be written and (unless
    ``--read-only``) a ``--loopsim`` that is not an executable, before any work."""
    from loopsim import validation

    try:
        validation.check_output_file("--out", args.out)
    except ValueError as exc:
        fail(exc)
    if not args.read_only and shutil.which(args.loopsim) is None:
        fail(f"--loopsim {args.loopsim!r} is not an executable (give the loopsim that runs "
             "the sweeps, or --read-only to tabulate the finished ones)")


#: The columns that name a row of the convergence table.
ROW_KEY = ("g0", "theta0_deg", "setting")


def row_keys(frame):
    """The (g0, θ0, setting) rows of a convergence table, rounded past the last bit."""
    return storage.study_keys(frame, ROW_KEY)


def sweep_keys(setting, g0, theta0):
    """The rows a sweep of ``setting`` over ``g0`` (comma-separated) at ``theta0`` gives."""
    values = g0.split(",")
    return storage.study_keys({"g0": values, "theta0_deg": [float(theta0)] * len(values),
                               "setting": [setting] * len(values)}, ROW_KEY)


def refuse_if_shrinking(out, keys, runs):
    """Exit (one line, status 2) where the table at ``out`` holds rows that ``keys`` lacks:
    a partial run never replaces a fuller table."""
    try:
        have, lost = storage.keys_a_write_would_drop(out, keys, ROW_KEY)
    except ValueError as exc:
        fail(f"{exc}: nothing written over it; give --out another place")
    if lost:
        fail(f"the finished sweeps in {runs!r} give {len(have) - len(lost)} of the "
             f"{len(have)} rows (cell and setting) of {out!r}: writing would drop "
             f"{len(lost)}; finish the other sweeps, or give --out another place (a partial "
             "run never replaces a fuller table)")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", default=os.path.join("runs", "convergence"))
    parser.add_argument("--threads", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--loopsim", default="loopsim", help="the loopsim executable that runs "
                        "the sweeps (a frozen install keeps the study on one code version)")
    parser.add_argument("--out", default=os.path.join("data", "convergence_top.parquet"))
    parser.add_argument("--read-only", action="store_true",
                        help="run nothing: tabulate the sweeps that have finished")
    args = parser.parse_args()
    check_places(args)
    if not args.read_only:  # every sweep runs: the rows all of them give
        refuse_if_shrinking(args.out, set().union(*(sweep_keys(setting, g0, theta0) for
                                                    _, setting, g0, theta0 in SWEEPS)),
                            args.runs)
    frames, finished = {}, []
    for name, setting, g0, theta0 in SWEEPS:
        path = os.path.join(args.runs, name)
        if not args.read_only:
            command = sweep_command(args.loopsim, args.runs, name, setting, g0, theta0,
                                    args.threads)
            print("$ " + " ".join(command), flush=True)
            if subprocess.call(command) not in (0, 1):
                sys.exit(f"convergence_study: the sweep into {path} did not finish")
        try:
            frame = loopsim.read_results(path)
        except (FileNotFoundError, ValueError):
            print(f"{name}: not finished, left out")
            continue
        if len(frame) < SEEDS * len(g0.split(",")):
            print(f"{name}: {len(frame)} of {SEEDS * len(g0.split(','))} cases, left out")
            continue
        finished.append(name)
        frames[setting] = pd.concat([frames.get(setting), cell_rows(frame)], ignore_index=True)
    if not frames:
        sys.exit("convergence_study: no sweep has finished")
    refuse_if_shrinking(args.out, set().union(*(
        row_keys(frame.assign(setting=setting)) for setting, frame in frames.items())),
        args.runs)
    table = tabulate(frames)
    meta = dict(ensemble=ENSEMBLE, seeds=f"0-{SEEDS - 1}", sweeps=finished,
                settings={k: " ".join(v) for k, v in SETTINGS.items()}, baselines=BASELINE,
                intervals="95% Wilson (p), Newcombe hybrid score (p differences), percentile "
                          "bootstrap (quantiles); verdict with Bonferroni intervals",
                certain=f"95% Wilson lower end >= {dd.CERTAIN_LOWER}",
                power_of_detectable=dd.POWER, loopsim_version=loopsim.__version__)
    arrow = pa.Table.from_pandas(table, preserve_index=False)
    arrow = arrow.replace_schema_metadata(storage.provenance(
        loopsim_convergence=json.dumps(meta)))
    os.makedirs(os.path.dirname(args.out) or ".", exist_ok=True)
    storage.write_table_atomically(storage.described(arrow, columns.CONVERGENCE_COLUMNS),
                                   args.out)
    with pd.option_context("display.width", 200, "display.max_columns", 30):
        shown = ["g0", "theta0_deg", "setting", "baseline", "seeds", "p_3d", "p_steady",
                 "tilt_q50", "certain_regime"] + [c for c in ("verdict",) if c in table]
        print(table[shown].to_string())
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
