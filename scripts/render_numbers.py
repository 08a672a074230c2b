"""Fill the measured numbers of README.md and docs/ from the committed tables.

Usage: python scripts/render_numbers.py [--check]

A number a page quotes from a study is written between two markers,
``<!-- num:KEY -->value<!-- /num -->``; ``KEY`` names a function of :data:`NUMBERS`
that computes the value from a committed table under ``data/`` (never from a run made
now).  The script rewrites every marked value in README.md and docs/**/*.md from those
functions; the rest of the pages is prose, kept as it is.  ``--check`` writes nothing and
exits 1, naming each span, if a page differs from its table or names a key that does not
exist (tests/test_render_numbers.py runs it).

The tables:

* ``data/phase_n6_cases.parquet``: the n = 6 grid (``loopsim sweep --g0 10:350:15
  --theta0 6:90:15 --n 6 --method rkf45 --no-twin``), one row per case, written by
  ``python scripts/paper_comparison.py --save-grids data``, with the same grid at n = 4
  (rkf45) and n = 8 (radau5) beside it (``phase_n4_cases``, ``phase_n8_cases``: Fig. 9).
  Their rows are not resolved, so their counts move with rounding (another machine or
  BLAS may move a few cases between regimes); each table is the run on the commit its
  metadata names.
* ``data/seeds_auto_grid_summary.parquet``: the main job's 72 points at ``--seeds auto``.
* ``data/paper_range_runs/paper_range_top24``: the runs of g0 = 252.9-350 at 24-30 deg.
* ``data/convergence_top.parquet`` and ``data/convergence_runs``: the convergence study at
  the top of the range.
* ``data/rest_study.parquet``: the run-to-rest study (``scripts/rest_study.py``).
* ``data/paper_range_overview.parquet``: the paper's 225 cells, each from its best
  committed study (``scripts/range_overview.py``).
* ``data/rest_window.json``: where loops can rest, ``loopsim rest-window --g0 10:350:15
  --json`` (tests/test_rest_window.py checks it against the code).
"""
import json
import argparse
import functools
import glob
import os
import re
import sys

import numpy as np
import pandas as pd

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.path.join(ROOT, "data")
#: A marked number: its key and its value as the page states it.
SPAN = re.compile(r"<!-- num:([\w.\-]+) -->(.*?)<!-- /num -->", re.S)
#: The circle's in-plane threshold (docs/stability.md): a terminal q below it ends circular.
Q_STAR = 8.9001
#: What paper-comparison calls a near-horizontal circle.
FLAT_TILT_DEG, ROUND_ASPECT = 15.0, 1.05
#: The paper's grid above g0 = 250 at 24-90 deg: 5 values of g0 (252.9-350) x 12 of theta0.
TOP_CELLS = 5 * 12


# ---------------------------------------------------------------------------------
# The tables, read once.

@functools.lru_cache(maxsize=None)
def table(name):
    """A committed table of data/ (a Parquet file, or a sweep directory through
    ``loopsim.read_results``)."""
    path = os.path.join(DATA, name)
    if os.path.isdir(path):
        import loopsim

        return loopsim.read_results(path)
    return pd.read_parquet(path)


def n6():
    return table("phase_n6_cases.parquet")


def n6_regime(regime):
    frame = n6()
    return frame[frame["regime"] == regime]


def grid():
    return table("seeds_auto_grid_summary.parquet")


def top24_first_round():
    frame = table(os.path.join("paper_range_runs", "paper_range_top24"))
    return frame[frame["round"] == 0]


def convergence():
    return table("convergence_top.parquet")


# ---------------------------------------------------------------------------------
# Formats.

def count(value):
    """An integer with a thin space every three digits, as the pages write them."""
    return f"{int(value):,}".replace(",", " ")


def fixed(digits):
    return lambda value: f"{value:.{digits}f}"


def quartiles(values, digits):
    return " / ".join(f"{v:.{digits}f}" for v in np.quantile(values, [0.25, 0.5, 0.75]))


def span(values, digits):
    """"a–b", from the smallest to the largest value."""
    return f"{np.min(values):.{digits}f}–{np.max(values):.{digits}f}"


def per_case_cost(regime_column):
    """Seconds of wall time per case at the main job's points whose every seed ended in
    one regime (``wall_s`` over ``seeds``), median and largest."""
    frame = grid()
    points = frame[frame[regime_column] == 1]
    return points["wall_s"] / points["seeds"]


def seconds(value):
    return f"{value:.2g} s" if value < 1 else f"{value:.0f} s" if value >= 10 else f"{value:.1f} s"


# ---------------------------------------------------------------------------------
# The numbers, by key: each a function of the tables, returning the text a page shows.

def _n6_counts():
    frame, d3 = n6(), n6_regime("3d")
    flat = d3["theta_final_deg"] < FLAT_TILT_DEG
    low = frame[frame["q_final"] < Q_STAR]
    inplane = n6_regime("in-plane")
    band = frame[(frame["q0"] > 10.5) & (frame["q0"] < 18.5)]
    nonstable = frame[frame["regime"] != "stable"]
    return {
        "n6.cases": count(len(frame)),
        "n6.3d": count(len(d3)),
        "n6.in-plane": count(len(inplane)),
        "n6.stable": count(len(n6_regime("stable"))),
        "n6.unresolved": count((~frame["resolved"]).sum()),
        "n6.unresolved-3d": count((~d3["resolved"]).sum()),
        "n6.unresolved-in-plane": count((~inplane["resolved"]).sum()),
        "n6.unresolved-stable": count((~n6_regime("stable")["resolved"]).sum()),
        "n6.resolved": count(frame["resolved"].sum()),
        "n6.3d-less-tilted": count((d3["theta_final_deg"] < d3["theta0_deg"]).sum()),
        "n6.3d-less-tilted-percent": f"{100 * (d3['theta_final_deg'] < d3['theta0_deg']).mean():.0f} %",
        "n6.3d-flat": count(flat.sum()),
        "n6.3d-circles": count((flat & (d3["aspect_ratio"] < ROUND_ASPECT)).sum()),
        "n6.3d-circles-percent": f"{100 * (flat & (d3['aspect_ratio'] < ROUND_ASPECT)).mean():.0f} %",
        "n6.3d-tilt-quartiles": quartiles(d3["theta_final_deg"], 1),
        "n6.3d-aspect-quartiles": quartiles(d3["aspect_ratio"], 2),
        "n6.3d-q-final-span": f"{d3['q_final'].min():.1f} to {d3['q_final'].max():.0f}",
        "n6.steady": count((frame["stop_reason"] == "steady").sum()),
        "n6.moving": count((frame["stop_reason"] == "t_end").sum()),
        "n6.moving-3d": count((d3["stop_reason"] == "t_end").sum()),
        "n6.low-q": count(len(low)),
        "n6.low-q-circles": count((low["aspect_ratio"] <= 1.01).sum()),
        "n6.low-q-others": count((low["aspect_ratio"] > 1.01).sum()),
        "n6.low-q-others-steady": count(((low["aspect_ratio"] > 1.01)
                                         & (low["stop_reason"] == "steady")).sum()),
        "n6.3d-length-error-median": f"{d3['length_error_max'].median():.3f}",
        "n6.3d-length-error-max": f"{d3['length_error_max'].max():.2f}",
        "n6.settling-max-stable": f"{n6_regime('stable')['settling_angle_deg'].max():.4f}°",
        "n6.settling-max-in-plane": f"{inplane['settling_angle_deg'].max():.2f}°",
        "n6.settling-max-3d": f"{d3['settling_angle_deg'].max():.2f}°",
        "n6.largest-stable-q0": f"{n6_regime('stable')['q0'].max():.2f}",
        "n6.smallest-nonstable-q0": f"{nonstable['q0'].min():.2f}",
        "n6.smallest-3d-q0": f"{d3['q0'].min():.2f}",
        "n6.in-plane-q0-span": span(inplane["q0"], 2),
        "n6.band-cases": count(len(band)),
        "n6.band-3d": count((band["regime"] == "3d").sum()),
        "n6.band-in-plane": count((band["regime"] == "in-plane").sum()),
    }


def _fig9_counts():
    """Fig. 9's grids at n = 4 (rkf45) and n = 8 (radau5) beside the n = 6 one
    (``data/phase_n<n>_cases.parquet``): ``fig9.n<n>.*``."""
    out = {}
    for n in (4, 8):
        frame = table(f"phase_n{n}_cases.parquet")
        d3 = frame[frame["regime"] == "3d"]
        flat = (d3["theta_final_deg"] < FLAT_TILT_DEG) & (d3["aspect_ratio"] < ROUND_ASPECT)
        out.update({f"fig9.n{n}.3d": count(len(d3)),
                    f"fig9.n{n}.in-plane": count((frame["regime"] == "in-plane").sum()),
                    f"fig9.n{n}.failed": count((frame["status"] != "ok").sum()),
                    f"fig9.n{n}.3d-circles": count(flat.sum()),
                    f"fig9.n{n}.boundary": (
                        f"{frame[frame['regime'] == 'stable']['q0'].max():.2f} / "
                        f"{frame[frame['regime'] != 'stable']['q0'].min():.2f}")})
    return out


def _n6_labels():
    """How the regime thresholds (1 deg of tilt, 0.01 of aspect ratio) cut the n = 6 grid."""
    frame = n6()
    tilt = (frame["theta_final_deg"] - frame["theta0_deg"]).abs()
    aspect = (frame["aspect_ratio"] - frame["aspect_ratio_initial"]).abs()
    small, middle = frame[tilt < 0.1], frame[(tilt >= 0.1) & (tilt <= 1)]
    continuum = frame[(tilt > 1) & (tilt <= 5)]
    return {
        "n6.tilt-below-0.1": count(len(small)),
        "n6.tilt-below-0.1-stable": count((small["regime"] == "stable").sum()),
        "n6.tilt-below-0.1-in-plane": count((small["regime"] == "in-plane").sum()),
        "n6.tilt-0.1-to-1": count(len(middle)),
        "n6.tilt-0.1-to-1-regimes": ", ".join(sorted(set(middle["regime"]))),
        "n6.tilt-0.1-to-1-q0": span(middle["q0"], 1),
        "n6.tilt-1-to-5": count(len(continuum)),
        "n6.tilt-above-10": count((tilt > 10).sum()),
        "n6.aspect-within-0.01": count((aspect <= 0.01).sum()),
        "n6.aspect-above-0.2": count((aspect > 0.2).sum()),
        "n6.stable-length-error-max": f"{n6_regime('stable')['length_error_max'].max():.1e}",
    }


def _grid_costs():
    return {
        "grid.cost-stable": seconds(per_case_cost("p_stable").median()),
        "grid.cost-in-plane": seconds(per_case_cost("p_in_plane").median()),
        "grid.cost-3d": seconds(per_case_cost("p_3d").median()),
        "grid.cost-3d-max": seconds(per_case_cost("p_3d").max()),
    }


def _top_costs():
    runs = top24_first_round()
    return {
        "top.runs": count(len(runs)),
        "top.sample-median": seconds(runs["wall_s"].median()),
        "top.sample-span": f"{runs['wall_s'].min():.1f}–{runs['wall_s'].max():.0f} s",
        "top.n-used": "–".join(str(int(v)) for v in sorted({runs["n_used"].min(), runs["n_used"].max()})),
        "top.twin-over-run": f"{runs['twin_nfev'].sum() / runs['nfev'].sum():.2f}×",
        "top.unsteady": count((runs["terminal_state"] == "unsteady").sum()),
        # the 60 cells of g0 >= 252.9 at 24-90 deg, 8 seeds each, at the median sample
        "top.cells60-seeds8-hours": f"{TOP_CELLS * 8 * runs['wall_s'].median() / 3600:.0f} h",
        "top.cells60-seeds8-hours-twins": f"{TOP_CELLS * 8 * runs['wall_s'].median() * (1 + runs['twin_nfev'].sum() / runs['nfev'].sum()) / 3600:.0f} h",
    }


def _tumbling_samples():
    """What a sample costs at (350, 18 deg) on the current radau5 (the convergence study's
    ``jmid_t18``: the defaults with the Jacobian inside the step), 16 seeds to t = 10."""
    runs = table(os.path.join("convergence_runs", "jmid_t18"))
    cell = runs[(runs["g0"].round(1) == 350) & (runs["theta0_deg"] == 18)]
    return {
        "conv.tumbling-350-seeds": count(len(cell)),
        "conv.tumbling-350-median": seconds(cell["wall_s"].median()),
        "conv.tumbling-350-max": seconds(cell["wall_s"].max()),
    }


def _convergence():
    frame = convergence()
    loose = frame[frame["setting"] == "jmid_rtol1e-3"]
    probabilities = loose[[c for c in frame.columns if c.startswith("delta_p_")
                           and c.endswith("_detectable")]].to_numpy()
    return {
        "conv.rtol1e-3-detectable-p": span(probabilities[np.isfinite(probabilities)], 2),
        "conv.rtol1e-3-detectable-tilt": " and ".join(
            f"{v:.1f}°" for v in sorted(loose["delta_tilt_q50_detectable"])),
        "conv.rtol1e-3-verdicts": ", ".join(sorted(set(loose["verdict"]))),
        "conv.rtol1e-3-cells": " and ".join(
            f"({g:g}, {t:g}°)" for g, t in sorted(zip(loose["g0"].round(1), loose["theta0_deg"]))),
    }


def _rest_window():
    """The losses of stability along the steady branch and the tilt windows of the
    paper's g0 grid (``data/rest_window.json``)."""
    with open(os.path.join(DATA, "rest_window.json"), encoding="utf-8") as handle:
        window = json.load(handle)
    out_of_plane, in_plane, fold = window["losses"]
    rows = ["| g0 | q0 = g0 / 3 at 90° | window θ_low–θ_high (deg) |", "|--:|--:|--|"]
    for row in window["windows"]:
        low = "none (every rest a circle)" if row["theta_low_deg"] is None else \
            f"{row['theta_low_deg']:.2f}–{row['theta_high_deg']:.2f}"
        rows.append(f"| {row['g0']:.1f} | {row['g0'] / 3:.1f} | {low} |")
    return {
        "rest.n": str(window["n"]),
        "rest.q-circle": f"{window['q_circle']:.4f}",
        "rest.hopf-out-q": f"{out_of_plane['q']:.5f}",
        "rest.hopf-out-frequency": f"{out_of_plane['frequency']:.3f}",
        "rest.hopf-in-q": f"{in_plane['q']:.5f}",
        "rest.hopf-in-frequency": f"{in_plane['frequency']:.3f}",
        "rest.fold-q": f"{fold['q']:.2f}",
        "rest.window-table": "\n\n" + "\n".join(rows) + "\n\n",
    }


def _interval(value, low, high, digits, unit=""):
    if not np.isfinite(value):
        return "not reached"
    ends = ", ".join("beyond the runs" if not np.isfinite(v) else f"{v:.{digits}f}"
                     for v in (low, high))
    return f"{value:.{digits}f}{unit} [{ends}]"


def _rest_range():
    """The paper's empty cells run to rest as far as they got
    (``data/paper_range_rest_summary.parquet``: ``loopsim summary`` of the
    ``data/rest_runs/range_rest_t*`` sweeps): ``rest.range-table``, ``rest.range-cells``."""
    path = os.path.join(DATA, "paper_range_rest_summary.parquet")
    if not os.path.exists(path):
        return {}
    frame = pd.read_parquet(path)
    rows = ["| g0, θ0 | seeds | P(3D) | at rest by t = 40 | P(at rest by t = 10) "
            "| median settling time | at rest: inside / below / outside | median tilt (deg) |",
            "|---|--:|--:|--:|---|---|--:|---|"]
    for _, r in frame.iterrows():
        rows.append(f"| ({r['g0']:.1f}, {r['theta0_deg']:.0f}°) | {int(r['seeds'])} | "
                    f"{r['p_3d']:.2f} | {int(r['at_rest'])} of {int(r['rest_observed'])} | "
                    + _interval(r["p_rest_t10"], r["p_rest_t10_low"], r["p_rest_t10_high"], 2)
                    + " | " + _interval(r["t_rest_median"], r["t_rest_median_low"],
                                        r["t_rest_median_high"], 1)
                    + f" | {int(r['rest_inside'])} / {int(r['rest_below'])} / "
                      f"{int(r['rest_outside'])} | "
                    + _interval(r["tilt_median"], r["tilt_median_low"], r["tilt_median_high"], 1)
                    + " |")
    return {"rest.range-table": "\n\n" + "\n".join(rows) + "\n\n",
            "rest.range-cells": count(len(frame))}


def _rest_study():
    """Per cell of the run-to-rest study: ``rest.<g0>-<theta0>.<statistic>``, and the
    table of every cell (``rest.study-table``)."""
    path = os.path.join(DATA, "rest_study.parquet")
    if not os.path.exists(path):
        return {}
    frame = pd.read_parquet(path)
    out, rows = {}, [
        "| g0, θ0 | q0 | at rest by t = 40 | P(at rest by t = 10) | median settling time "
        "| 95 % at rest by | escape rate after t = 10 (per t_u) | window (deg) "
        "| at rest: inside / below / outside | P(3D) at rest | tilt quartiles at rest (deg) |",
        "|---|--:|--:|---|---|--:|---|---|--:|--:|---|"]
    for _, r in frame.iterrows():
        key = f"rest.{r['g0']:.0f}-{r['theta0_deg']:.0f}"
        cell = {
            "at-rest": f"{r['at_rest']} of {r['rest_observed']}",
            "moving": count(r["moving_at_t_max"]),
            "p10": _interval(r["p_rest_t10"], r["p_rest_t10_low"], r["p_rest_t10_high"], 2),
            "median": _interval(r["t_rest_median"], r["t_rest_median_low"],
                                r["t_rest_median_high"], 1),
            "q95": "not reached" if not np.isfinite(r["t_rest_q95"]) else f"{r['t_rest_q95']:.1f}",
            "escape": (f"{r['escape_events']} events: too few"
                       if not np.isfinite(r["escape_rate"]) else
                       _interval(r["escape_rate"], r["escape_rate_low"], r["escape_rate_high"], 2)),
            "window": f"{r['window_low_deg']:.2f}–{r['window_high_deg']:.2f}",
            "where": f"{r['rest_inside']} / {r['rest_below']} / {r['rest_outside']}",
            "p3d": f"{r['p_3d']:.2f}",
            "tilts": " / ".join(f"{r[c]:.1f}" for c in ("tilt_q25", "tilt_median", "tilt_q75")),
        }
        out.update({f"{key}.{k}": v for k, v in cell.items()})
        rows.append(f"| ({r['g0']:.1f}, {r['theta0_deg']:.0f}°) | {r['q0']:.1f} | "
                    + " | ".join(cell[k] for k in ("at-rest", "p10", "median", "q95", "escape",
                                                    "window", "where", "p3d", "tilts")) + " |")
        if isinstance(r.get("baseline"), str):
            out[f"{key}.verdict"] = r["verdict"]
            out[f"{key}.delta-p3d"] = _interval(r["delta_p_3d"], r["delta_p_3d_low"],
                                                r["delta_p_3d_high"], 2)
            out[f"{key}.delta-tilt50"] = _interval(r["delta_tilt_q50"], r["delta_tilt_q50_low"],
                                                   r["delta_tilt_q50_high"], 1, "°")
            out[f"{key}.detectable-p3d"] = f"{r['delta_p_3d_detectable']:.2f}"
            out[f"{key}.detectable-tilt50"] = f"{r['delta_tilt_q50_detectable']:.1f}°"
            out[f"{key}.base-p10"] = f"{r['base_p_steady']:.2f}"
    out["rest.study-table"] = "\n\n" + "\n".join(rows) + "\n\n"
    out["rest.cells"] = count(len(frame))
    out["rest.loops-at-rest"] = count(frame["at_rest"].sum())
    out.update(_rest_range())
    return out


def _range_overview():
    """The paper's 225 cells, each from its best committed study
    (``data/paper_range_overview.parquet``, ``scripts/range_overview.py``): ``range.*``
    counts, and ``range.top-table``, the cells of g0 >= 252.9 as a grid."""
    path = os.path.join(DATA, "paper_range_overview.parquet")
    if not os.path.exists(path):
        return {}
    frame = pd.read_parquet(path)
    known = frame[frame["seeds"] > 0]
    rest = known[known["t_max"] > 10]
    top = frame[frame["g0"] > 250]
    g0s = sorted(top["g0"].unique())
    rows = ["| θ0 | " + " | ".join(f"g0 = {g:.1f}" for g in g0s) + " |",
            "|---|" + "---|" * len(g0s)]
    for theta0, cells in top.groupby("theta0_deg"):
        entries = []
        for _, r in cells.sort_values("g0").iterrows():
            if r["seeds"] == 0:
                entries.append("not run")
                continue
            where = "to rest" if r["t_max"] > 10 else (
                "t = 10, unfinished" if "unfinished" in r["source"] else "t = 10")
            entries.append(f"{r['p_3d']:.2f} / {r['p_not_rest_t10']:.2f} "
                           f"({int(r['seeds'])}, {where})")
        rows.append(f"| {theta0:.0f}° | " + " | ".join(entries) + " |")
    moving = known[known["p_not_rest_t10"] > 0]
    with open(os.path.join(DATA, "rest_window.json"), encoding="utf-8") as handle:
        q_loss = json.load(handle)["q_loss"]   # the stable branch's upper edge
    above = known[known["q0"] > q_loss]
    return {"range.known": count(len(known)), "range.cells": count(len(frame)),
            "range.rest-cells": count(len(rest)),
            "range.horizon-cells": count(len(known) - len(rest)),
            "range.not-run": count(len(frame) - len(known)),
            "range.not-run-top": count(int((top["seeds"] == 0).sum())),
            "range.moving-cells": count(len(moving)),
            "range.rest-outside": count(rest["rest_outside"].sum()),
            "range.rest-loops": count(rest["at_rest"].sum()),
            "range.above-edge-cells": count(len(above)),
            "range.above-edge-moving": (f"{above['p_not_rest_t10'].min():.2f}–"
                                        f"{above['p_not_rest_t10'].max():.2f}"),
            "range.top-table": "\n\n" + "\n".join(rows) + "\n\n"}


#: The paper's grid of initial tilts (deg): one range sweep per tilt.
RANGE_THETA0 = tuple(range(6, 91, 6))


@functools.lru_cache(maxsize=None)   # two groups read them: once
def _range_sweeps():
    """{theta0: (rows, cases)} of the range sweeps under ``data/rest_runs``
    (``range_rest_t<θ0>``, one per tilt of :data:`RANGE_THETA0`, run to rest), those
    started so far: their finished rows and how many cases each holds in all."""
    from loopsim import storage

    found = {}
    for theta0 in RANGE_THETA0:
        name = os.path.join("rest_runs", f"range_rest_t{theta0}")
        if os.path.isdir(os.path.join(DATA, name)):
            cases = storage.read_sweep_file(os.path.join(DATA, name))["config"]["cases"]
            found[theta0] = (table(name), len(cases))
    return found


def _range_rest_cost():
    """What a loop run to rest costs at the top of the range: ``wall_s`` of the finished
    range sweeps' rows (2 shared cores; a sweep still running has its slow cases still
    to come, so it is left out), per loop and in all, and over the cells at θ0 >= 24°."""
    frames = {t: rows for t, (rows, cases) in _range_sweeps().items() if len(rows) == cases}
    if not frames:
        return {}
    rows = pd.concat(frames.values())
    walls = rows["wall_s"].to_numpy(float)
    empty = rows[rows["theta0_deg"] >= 24]   # the cells no study had answered before
    return {"range.rest-runs": count(walls.size),
            "range.rest-tilts": f"{min(frames)}–{max(frames)}°",
            "range.rest-sample-median": f"{np.median(walls):.0f} s",
            "range.rest-sample-span": f"{walls.min():.2g}–{walls.max():.0f} s",
            "range.rest-cell-hours": f"{8 * walls.mean() / 3600:.2f} h",
            "range.rest-total-hours": f"{walls.sum() / 3600:.1f} h",
            "range.rest-empty-cells": count(empty.groupby(["g0", "theta0_deg"]).ngroups),
            "range.rest-empty-hours": f"{empty['wall_s'].sum() / 3600:.1f} h"}


def _range_rest_progress():
    """How far the range sweeps have got: ``range.rest-rows-done`` (the finished tilts)
    and ``range.rest-rows-pending`` (each unfinished tilt with its runs committed so
    far, or "none")."""
    sweeps = _range_sweeps()
    done = [t for t, (rows, cases) in sweeps.items() if len(rows) == cases]
    pending = [f"{t}° (not started)" if t not in sweeps else
               f"{t}° ({len(sweeps[t][0])} of {sweeps[t][1]} runs)"
               for t in RANGE_THETA0 if t not in done]
    return {"range.rest-rows-done": ", ".join(f"{t}°" for t in done) or "none",
            "range.rest-rows-pending": ", ".join(pending) or "none"}


def _counts(share, trials):
    """The whole count behind a share of ``trials`` (a summary stores shares)."""
    hits = share * trials
    assert abs(hits - round(hits)) < 1e-9, (share, trials)
    return int(round(hits))


def _range_horizon_regimes():
    """The regime shares at t = 10 against those run to rest, at the cells in both
    ``data/paper_range_summary.parquet`` (t = 10, ``--seeds auto``, an earlier code) and
    ``data/paper_range_rest_summary.parquet`` (run to rest): per cell P(in-plane) and
    P(3D) each way with the Newcombe interval of P(3D) run to rest minus at t = 10, and
    the median tilts (``range.t10-vs-rest-table``), and the differences pooled over the cells whose two
    samples have the same number of seeds (seeds 0 to K − 1 both), with the smallest
    difference they could detect.  Pooling can hide opposite changes in two cells; the
    table shows each.  Where the two samples' starts coincide they are positively
    correlated, and the unpaired intervals are then conservative."""
    from loopsim import distribution_differences as dd

    def keyed(frame):
        return frame.assign(g0=frame["g0"].round(6), theta0_deg=frame["theta0_deg"].round(6))

    ten = keyed(pd.read_parquet(os.path.join(DATA, "paper_range_summary.parquet")))
    rest = keyed(pd.read_parquet(os.path.join(DATA, "paper_range_rest_summary.parquet")))
    both = ten.merge(rest, on=["g0", "theta0_deg"], suffixes=("_10", "_rest"))
    rows = ["| g0, θ0 | seeds: t = 10 / to rest | P(in-plane): t = 10 / to rest "
            "| P(3D): t = 10 / to rest | P(3D) to rest − at t = 10 "
            "| median tilt (deg): t = 10 / to rest |",
            "|---|--:|--:|--:|---|--:|"]
    pooled = {regime: [0, 0, 0] for regime in ("in_plane", "3d")}
    for _, r in both.iterrows():
        n10, nrest = int(r["seeds_10"]), int(r["seeds_rest"])
        k10, krest = _counts(r["p_3d_10"], n10), _counts(r["p_3d_rest"], nrest)
        low, high = dd.newcombe_interval(k10, n10, krest, nrest)
        rows.append(f"| ({r['g0']:.1f}, {r['theta0_deg']:.0f}°) | {n10} / {nrest} | "
                    f"{r['p_in_plane_10']:.2f} / {r['p_in_plane_rest']:.2f} | "
                    f"{r['p_3d_10']:.2f} / {r['p_3d_rest']:.2f} | "
                    f"{krest / nrest - k10 / n10:+.2f} [{low:+.2f}, {high:+.2f}] | "
                    f"{r['tilt_median_10']:.1f} / {r['tilt_median_rest']:.1f} |")
        if n10 == nrest:
            for regime, sums in pooled.items():
                sums[0] += _counts(r[f"p_{regime}_10"], n10)
                sums[1] += _counts(r[f"p_{regime}_rest"], nrest)
                sums[2] += n10
    out = {"range.t10-vs-rest-cells": count(len(both)),
           "range.t10-vs-rest-table": ("\n\n" + "\n".join(rows) + "\n\n") if len(both)
           else "none yet"}
    for regime, (k10, krest, trials) in pooled.items():
        key = f"range.t10-vs-rest-{regime.replace('_', '-')}"
        if not trials:
            out[key], out[key + "-detectable"] = "no cell yet", "none"
            continue
        low, high = dd.newcombe_interval(k10, trials, krest, trials)
        out[key] = (f"{k10} → {krest} of {trials}: {(krest - k10) / trials:+.2f} "
                    f"[{low:+.2f}, {high:+.2f}]")
        out[key + "-detectable"] = (
            f"{dd.detectable_probability_difference(k10 / trials, trials, trials):.2f}")
    return out


def _rest_samples():
    """The rows of every cell run to rest, each from the sweep the range overview
    (``data/paper_range_overview.parquet``) takes it from: its largest complete sample."""
    from loopsim import outcome_statistics

    overview = pd.read_parquet(os.path.join(DATA, "paper_range_overview.parquet"))
    cells, sweeps = [], {}
    for _, cell in overview[overview["t_max"] > 10].iterrows():
        source = os.path.relpath(cell["source"], "data")
        if source not in sweeps:
            sweeps[source] = outcome_statistics.complete_cells(table(source))
        cells.append(sweeps[source][(round(cell["g0"], 6), round(cell["theta0_deg"], 6))])
    return pd.concat(cells, ignore_index=True) if cells else None


#: Edges (t_u) of the windows after t = 10 in which the pooled escape rate is estimated
#: apart: one rate in all of them is an exponential (memoryless) tail.
TAIL_WINDOWS = (10.0, 15.0, 20.0, 40.0)


def _range_rest_pooled():
    """Every loop of the cells run to rest pooled (``range.pooled-*``): how many came to
    rest by t_max (and those that did not, with their ``terminal_state``), P(at rest by
    t = 10), the time by which 95 % rest, the latest settling time; and of the 3D loops'
    tail, the escape rate after t = 10 and in each window of :data:`TAIL_WINDOWS` with the
    p-value of one rate across them, and the most a tail at the rate's lower limit leaves
    moving at t_max of the loops moving at t = 10 (the other loops' escape rate apart)."""
    from loopsim import survival

    rows = _rest_samples()
    if rows is None:
        return {}
    pooled = survival.settling_statistics(rows)
    times, at_rest = survival.settling_times(rows)
    t_max = float(rows["t_end"].max())
    cells = rows.groupby(["g0", "theta0_deg"]).ngroups
    out = {"range.pooled-loops": count(pooled["rest_observed"]),
           "range.pooled-cells": count(cells),
           "range.pooled-at-rest": count(pooled["at_rest"]),
           "range.pooled-p10": _interval(pooled["p_rest_t10"], pooled["p_rest_t10_low"],
                                         pooled["p_rest_t10_high"], 2),
           "range.pooled-q95": (f"{pooled['t_rest_q95']:.1f}"
                                if np.isfinite(pooled["t_rest_q95"]) else "not reached"),
           "range.pooled-latest": (f"{times[at_rest].max():.1f}" if at_rest.any()
                                   else "none at rest"),
           "range.pooled-t-max": f"{t_max:g}"}
    # the tail: the 3D loops tumble before they rest; a stable or in-plane loop not yet
    # at rest approaches it slowly near the thresholds, at a rate of its own
    tumbling = rows["regime"].eq("3d")
    out["range.pooled-3d-loops"] = count(int(tumbling.sum()))
    slow_times, slow_at_rest = survival.settling_times(rows[~tumbling])
    rate, low, high, events, _ = survival.escape_rate(slow_times, slow_at_rest)
    out["range.pooled-slow-escape"] = (f"{_interval(rate, low, high, 3)} ({events} events)"
                                       if np.isfinite(rate) else f"{events} events: too few")
    times, at_rest = survival.settling_times(rows[tumbling])
    rate, low, high, events, _ = survival.escape_rate(times, at_rest)
    out["range.pooled-escape"] = (f"{_interval(rate, low, high, 2)} ({events} events)"
                                  if np.isfinite(rate) else f"{events} events: too few")
    windows = survival.window_escape_rates(times, at_rest, TAIL_WINDOWS)
    out["range.pooled-escape-windows"] = "; ".join(
        f"({w.start:g}, {w.end:g}]: {_interval(w.rate, w.low, w.high, 2)} ({w.events} events)"
        for w in windows.itertuples())
    p_value = survival.one_rate_p_value(windows["events"], windows["exposure"])
    out["range.pooled-one-rate-p"] = f"{p_value:.2f}"
    out["range.pooled-one-rate"] = ("one rate fits" if p_value >= 0.05 else
                                    "the rate changes") if np.isfinite(p_value) else "untested"
    out["range.pooled-tail-left"] = (
        f"{np.exp(-low * (t_max - survival.PAPER_HORIZON)):.1g}" if np.isfinite(low)
        else "unknown")
    moving = rows[rows["stop_reason"].eq("t_end")]
    out["range.pooled-left"] = "; ".join(
        f"({r['g0']:.1f}, {r['theta0_deg']:.0f}°) seed {r['seed']}, {r['terminal_state']}"
        for _, r in moving.iterrows()) or "none"
    return out


#: Groups of keys, each computed together from one table; a key's function is its group's.
GROUPS = (_n6_counts, _n6_labels, _fig9_counts, _grid_costs, _top_costs, _tumbling_samples, _convergence,
          _rest_window, _rest_study, _range_overview, _range_rest_cost,
          _range_rest_pooled, _range_rest_progress, _range_horizon_regimes)


@functools.lru_cache(maxsize=None)
def numbers():
    """{key: the value's text} for every key of every group."""
    values = {}
    for group in GROUPS:
        found = group()
        clash = values.keys() & found.keys()
        assert not clash, f"{group.__name__} redefines {sorted(clash)}"
        values.update(found)
    return values


# ---------------------------------------------------------------------------------
# The pages.

def pages():
    """README.md and every Markdown page under docs/, as paths relative to the root."""
    names = ["README.md"] + sorted(
        os.path.relpath(p, ROOT) for p in glob.glob(os.path.join(ROOT, "docs", "**", "*.md"),
                                                      recursive=True))
    return names


def rendered(text, values):
    """(the text with every marked value replaced from ``values``, [problems])."""
    problems = []

    def fill(match):
        key, shown = match.group(1), match.group(2)
        if key not in values:
            problems.append(f"{key}: no such number")
            return match.group(0)
        if shown != values[key]:
            problems.append(f"{key}: the page says {shown!r}, the table {values[key]!r}")
        return f"<!-- num:{key} -->{values[key]}<!-- /num -->"

    return SPAN.sub(fill, text), problems


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true",
                        help="write nothing; exit 1 if a page differs from its table")
    args = parser.parse_args(argv)
    values, stale, unknown = numbers(), [], []
    for name in pages():
        path = os.path.join(ROOT, name)
        with open(path, encoding="utf-8") as handle:
            text = handle.read()
        new, problems = rendered(text, values)
        unknown += [f"{name}: {p}" for p in problems if p.endswith("no such number")]
        if new != text:
            stale += [f"{name}: {p}" for p in problems if not p.endswith("no such number")]
            if not args.check:
                with open(path, "w", encoding="utf-8") as handle:
                    handle.write(new)
    for line in unknown:
        print(line, file=sys.stderr)
    if args.check and stale:
        print("\n".join(stale) + "\nrun python scripts/render_numbers.py", file=sys.stderr)
        return 1
    return 1 if unknown else 0


if __name__ == "__main__":
    sys.exit(main())
