"""Outcomes as distributions: one row per cell of a sweep, from its seeds.

A *cell* is one point of the sweep's inputs with the seed left out: ``g0``,
``theta0_deg`` and every other input column of :data:`CELL_INPUTS` that takes more than
one value in the table (``model``, ``slenderness``, ``n``, ``rtol``, ``perturbation`` ...:
whatever a grid or a cases file can set per case).  A cell holds each seed at most once:
two rows with one seed in one cell differ in an input the table does not record (an
``initial`` shape, say), and are refused rather than merged.  Per cell:

* ``seeds``, ``resolved``, ``determined``, ``twinned``, ``steady``: how many rows, and
  how many of them are resolved and determined (``loopsim.outcomes``: a twin agreed;
  ``twinned`` of them ran a twin, the others' determinacy is unknown, and ``determined``
  is ``<NA>`` where no row did) and reached a steady state before ``t_end`` (unknown,
  ``<NA>``, where a row ran without the early stop: ``rows_tested``);
* ``p_<regime>`` for each regime, with its 95 % Wilson score interval (no continuity
  correction; ``scipy.stats.binomtest(k, N).proportion_ci(method="wilson")``)
  ``p_<regime>_low``, ``p_<regime>_high``:

      (p̂ + z²/2N ± z sqrt(p̂(1 − p̂)/N + z²/4N²)) / (1 + z²/N),  z = Φ⁻¹(0.975)

* the median and quartiles of the terminal tilt, aspect ratio and q (``tilt_*``,
  ``aspect_*``, ``q_final_*``), each median with a 95 % percentile-bootstrap interval
  (``scipy.stats.bootstrap(method="percentile")``, ``BOOTSTRAP_RESAMPLES`` resamples
  from ``numpy.random.default_rng(seed)``, so the table is reproducible);
* the cost: ``nfev`` and ``twin_nfev`` summed, ``wall_s`` summed.

Plain NumPy, SciPy and pandas: no integration happens here.
"""
import numpy as np
import pandas as pd

from . import survival
# The intervals, re-exported: ``outcome_statistics`` has always offered them.
from .intervals import (  # noqa: F401
    BOOTSTRAP_RESAMPLES, bootstrap_interval, percentile_bootstrap, wilson_interval,
)
from .outcomes import REGIMES

#: z of a two-sided 95 % interval, Φ⁻¹(0.975).
Z95 = 1.959963984540054
#: The outcome columns summarised by quantiles, and their prefixes in the summary.
OUTCOME_STATISTICS = (("theta_final_deg", "tilt"), ("aspect_ratio", "aspect"),
                      ("q_final", "q_final"))
#: The inputs that may define a cell (the seed never does): every input column of a
#: results table that a grid, a sweep option or a cases-file column can set per case.
CELL_INPUTS = ("g0", "theta0_deg", "model", "slenderness", "n", "t_end", "rtol", "atol", "w",
               "perturbation", "method")


def cell_columns(frame):
    """The inputs that define the cells of ``frame``: g0 and theta0_deg, and every other
    input of :data:`CELL_INPUTS` that varies."""
    return [c for c in CELL_INPUTS if c in frame and (c in ("g0", "theta0_deg")
                                                      or frame[c].nunique(dropna=False) > 1)]


def _key(key):
    """A groupby key as a tuple whose missing values (NaN, None) compare equal, so that
    cells of two tables pair up (NaN != NaN)."""
    key = key if isinstance(key, tuple) else (key,)
    return tuple(None if pd.isna(value) else value for value in key)


def cell_groups(frame, by):
    """[(key, rows)] of ``frame`` grouped into cells by the columns ``by`` (missing values a
    value of their own; keys as :func:`_key`); ValueError naming the first cell that holds
    one seed twice (rows that differ in an input the table does not tell apart)."""
    groups = [(_key(key), rows) for key, rows in frame.groupby(by, sort=True, dropna=False)]
    if "seed" in frame:
        for key, rows in groups:
            counts = rows["seed"].value_counts()
            if counts.max() > 1:
                cell = ", ".join(f"{c}={v}" for c, v in zip(by, key))
                raise ValueError(
                    f"cell ({cell}) holds seed {int(counts.idxmax())} {int(counts.max())} "
                    f"times: its rows differ in an input not among {list(by)} (a given "
                    "initial shape?); summarise them apart, or pass by= with that input")
    return groups


def complete_cells(frame):
    """{(g0, theta0_deg): rows} of the cells of a sweep's ``frame`` (from
    ``read_results``) whose every case has finished, the count each needs read from the
    sweep's case list (``frame.attrs["loopsim"]["sweep_config"]["cases"]``); keys rounded
    to 6 decimals, so that cells of two sweeps pair up whatever the last bits of g0.
    ValueError where the frame carries no case list."""
    try:
        cases = frame.attrs["loopsim"]["sweep_config"]["cases"]
    except (KeyError, TypeError):
        raise ValueError("the table carries no sweep case list (read it with "
                         "loopsim.read_results)") from None
    wanted = pd.DataFrame(cases).groupby(["g0", "theta0_deg"]).size()
    return {(round(float(g0), 6), round(float(theta0), 6)): rows
            for (g0, theta0), rows in frame.groupby(["g0", "theta0_deg"])
            if len(rows) == wanted.get((g0, theta0), -1)}


def steady_tested(frame):
    """Whether the rows of a results table were tested for a steady state (the early stop
    could end them, so ``stop_reason`` "steady" counts them): False where the table records
    that its sweep ran with ``--no-early-stop`` (``early_stop`` False in
    ``frame.attrs["loopsim"]["sweep_config"]``, as :func:`loopsim.read_results` gives it),
    True otherwise."""
    config = frame.attrs.get("loopsim", {}).get("sweep_config")
    return not (isinstance(config, dict) and config.get("early_stop") is False)


def rows_tested(rows, tested=True):
    """Whether every row of ``rows`` was tested for a steady state: its ``early_stop``
    (False: run with ``--no-early-stop``), or where a row does not record it (null, or no
    such column: a table read by other means than ``read_results``) ``tested``, the
    table's own (:func:`steady_tested`)."""
    if "early_stop" not in rows:
        return tested
    return bool(rows["early_stop"].astype(object).where(rows["early_stop"].notna(), tested)
                .astype(bool).all())


def _cell_row(rows, seed, tested=True, motion=True, window=None):
    trials = len(rows)
    twinned = int(rows["determined"].notna().sum())  # rows whose determinacy is known
    out = dict(seeds=trials, resolved=int(rows["resolved"].sum()),
               determined=int(rows["determined"].eq(True).sum()) if twinned else pd.NA,
               twinned=twinned)
    if "stop_reason" in rows:  # unknown (<NA>) where a row was never tested
        out["steady"] = (int(rows["stop_reason"].eq("steady").sum())
                         if rows_tested(rows, tested) else pd.NA)
    if motion:  # unknown (<NA>, NaN) where a row of the cell does not record it
        recorded = rows["terminal_state"].notna().all()
        unsteady = int(rows["terminal_state"].eq("unsteady").sum())
        out["unsteady"] = unsteady if recorded else pd.NA
        out["p_unsteady"] = unsteady / trials if recorded else float("nan")
        out["p_unsteady_low"], out["p_unsteady_high"] = (
            wilson_interval(unsteady, trials) if recorded else (float("nan"),) * 2)
    for regime in REGIMES:
        name = regime.replace("-", "_")
        hits = int((rows["regime"] == regime).sum())
        out[f"p_{name}"] = hits / trials
        out[f"p_{name}_low"], out[f"p_{name}_high"] = wilson_interval(hits, trials)
    for column, short in OUTCOME_STATISTICS:
        if column not in rows:
            continue
        values = rows[column].to_numpy(float)
        finite = values[np.isfinite(values)]
        quartiles = np.percentile(finite, [25, 50, 75]) if finite.size else [np.nan] * 3
        out[f"{short}_q25"], out[f"{short}_median"], out[f"{short}_q75"] = map(float, quartiles)
        out[f"{short}_median_low"], out[f"{short}_median_high"] = bootstrap_interval(
            finite, seed=seed)
    if "stop_reason" in rows and "t_final" in rows and rows_tested(rows, tested):
        out.update(survival.settling_statistics(rows))
        if window is not None:
            out.update(survival.window_counts(rows, window))
    for column in ("nfev", "twin_nfev", "wall_s"):
        out[column] = rows[column].sum() if column in rows else 0
    return out


def summarize(frame, by=None, seed=0, rest_window=None):
    """Outcomes as distributions: one row per cell of a results table, from its seeds.

    A cell is one point of the sweep's inputs with the seed left out: ``g0``,
    ``theta0_deg`` and every other input of ``CELL_INPUTS`` that takes more than one
    value in the table.  A cell holds each seed at most once (two rows with one seed
    differ in an input the table does not record, such as an ``initial`` shape, and are
    refused rather than merged).

    Parameters
    ----------
    frame : pandas.DataFrame
        A results table (``loopsim.read_results``), with at least ``regime``,
        ``resolved``, ``determined`` and the cell columns.
    by : list of str or None, default None
        The columns that define the cells; None: ``cell_columns`` (g0, theta0_deg and
        every other input that varies).
    seed : int, default 0
        Seed of the bootstrap's generator (the table is reproducible bit for bit).
    rest_window : loopsim.stability.rest_window.RestWindow or None, default None
        Where loops can rest (``loopsim.stability.rest_window.stability_losses``): with
        it, the rows that came to rest are counted inside, below and outside the tilt
        window at their g0 (``rest_inside``, ``rest_below``, ``rest_outside``).

    Returns
    -------
    pandas.DataFrame
        One row per cell, sorted by its inputs, with the columns of
        ``loopsim.columns.SUMMARY_COLUMNS``:

        * ``seeds``, ``resolved``, ``determined``, ``steady``: how many rows, and how
          many of them are resolved, determined, and reached a steady state before
          ``t_end`` (the others ran to ``t_end``, their "terminal" values the state
          there, or failed; ``steady`` only where ``frame`` has ``stop_reason``, and
          unknown, ``<NA>``, in a cell where a row ran with ``--no-early-stop``: its
          ``early_stop`` False, or where rows do not record it, ``steady_tested``);
        * ``unsteady`` and ``p_unsteady`` (with its Wilson interval): the rows still
          moving at their end (``terminal_state``, ``loopsim.late_motion``), only where
          some row of ``frame`` records it, and unknown (``<NA>``, NaN), never 0, in a
          cell where some row does not (rows written by an older release);
        * ``p_<regime>`` for each regime (stable, in_plane, 3d, failed), with its 95 %
          Wilson score interval ``p_<regime>_low``, ``p_<regime>_high``:
          (p̂ + z²/2N ± z sqrt(p̂(1 − p̂)/N + z²/4N²)) / (1 + z²/N), z = Φ⁻¹(0.975);
        * the quartiles of the terminal tilt (degrees), aspect ratio and q
          (``tilt_*``, ``aspect_*``, ``q_final_*``), each median with a 95 %
          percentile-bootstrap interval (``BOOTSTRAP_RESAMPLES`` resamples);
        * the settling statistics (``loopsim.survival``, where the rows were tested for
          a steady state): ``rest_observed``, ``at_rest``, P(at rest by t = 10)
          ``p_rest_t10`` with its interval, the Kaplan–Meier median settling time
          ``t_rest_median`` with its interval, ``t_rest_q95``, and the escape rate after
          t = 10 (``escape_rate``, its interval, ``escape_events``, ``tail_time``);
        * the cost: ``nfev``, ``twin_nfev`` and ``wall_s`` (seconds) summed.

        ``table.attrs["loopsim_summary"]`` records the cell columns and the bootstrap.

    Raises
    ------
    ValueError
        A column of ``by`` is missing, ``frame`` has no rows, or a cell holds one seed
        twice (the message names the cell).

    Examples
    --------
    Four seeds of one cell (docs/distributions.md summarises 16 seeds of four):

    >>> import loopsim
    >>> rows = loopsim.sweep(40.0, 30.0, "runs/four", n=6, t_end=0.5, seeds=4, twin=False)
    >>> loopsim.summarize(rows)[["g0", "theta0_deg", "seeds", "p_3d", "p_3d_high"]].round(3)
         g0  theta0_deg  seeds  p_3d  p_3d_high
    0  40.0        30.0      4   0.0       0.49
    """
    by = list(cell_columns(frame) if by is None else by)
    missing = [c for c in by if c not in frame]
    if missing:
        raise ValueError(f"no column(s) {missing} to group the cells by")
    if not len(frame):
        raise ValueError("no rows to summarise")
    tested = steady_tested(frame)
    motion = "terminal_state" in frame and bool(frame["terminal_state"].notna().any())
    rows = [dict(zip(by, key), **_cell_row(group, seed, tested, motion, rest_window))
            for key, group in cell_groups(frame, by)]
    table = pd.DataFrame(rows)
    if motion and table["unsteady"].isna().any():
        table["unsteady"] = table["unsteady"].astype("Int64")  # unknown: <NA>
    if table["determined"].isna().any():
        table["determined"] = table["determined"].astype("Int64")  # no twin ran: <NA>
    if "steady" in table and table["steady"].isna().any():
        table["steady"] = table["steady"].astype("Int64")  # unknown: <NA>, empty in Parquet
    table.attrs["loopsim_summary"] = dict(cells_by=by, bootstrap_seed=seed,
                                          bootstrap_resamples=BOOTSTRAP_RESAMPLES,
                                          interval="95 % (Wilson; percentile bootstrap)")
    return table


# ---- what a sweep's closing lines (``loopsim sweep``) and its report count ------------
#: The command a sweep's closing line and its report give for rerunning failed cases
#: (``{out}``: the sweep directory).
RERUN_COMMAND = "loopsim sweep --rerun-failed {out} --method radau5"
#: Columns of :func:`costliest` (those present in the table).
COST_COLUMNS = ("case_id", "round", "g0", "theta0_deg", "seed", "n_used", "method", "regime",
                "status", "wall_s", "nfev", "twin_nfev")


def _regime_counts(rows):
    return {str(k): int(v) for k, v in sorted(rows["regime"].value_counts().items())}


def not_recorded(frame, column):
    """How many rows of ``frame`` do not record ``column`` (a null value, or no such
    column: rows written by a release before the column existed, filled in by
    ``storage.read_results`` as null)."""
    return len(frame) if column not in frame else int(frame[column].isna().sum())


def outcome_counts(frame):
    """The counts of a results table (``read_results``) that ``loopsim sweep`` closes
    with: ``cases``; ``regimes`` ({regime: rows}); ``unresolved`` (rows not resolved at
    their n), ``undetermined`` (rows whose twin ends elsewhere) and ``unsteady`` (rows
    still moving at their end, ``terminal_state``), each with the regimes among them
    (``unresolved_regimes``, ``undetermined_regimes``, ``unsteady_regimes``); ``failed``
    (rows whose ``status`` is not "ok"); ``twinned`` (rows that ran a twin: the only ones
    whose ``determined`` is known).

    ``unsteady`` is None (unknown, never 0) where some row does not record
    ``terminal_state`` (written by an older release): ``unsteady_not_recorded`` says how
    many, and ``unsteady_recorded`` counts the unsteady rows among those that do (with
    ``unsteady_regimes``)."""
    unresolved = frame[~frame["resolved"].astype(bool)]
    undetermined = frame[frame["determined"].eq(False)]
    unsteady = (frame[frame["terminal_state"].eq("unsteady")] if "terminal_state" in frame
                else frame.iloc[:0])
    missing = not_recorded(frame, "terminal_state")
    return dict(cases=len(frame), regimes=_regime_counts(frame), unresolved=len(unresolved),
                unresolved_regimes=_regime_counts(unresolved), undetermined=len(undetermined),
                undetermined_regimes=_regime_counts(undetermined),
                unsteady=None if missing else len(unsteady), unsteady_recorded=len(unsteady),
                unsteady_not_recorded=missing, unsteady_regimes=_regime_counts(unsteady),
                failed=int((frame["status"] != "ok").sum()),
                twinned=int(frame["determined"].notna().sum()))


def undetermined_text(counts):
    """The count of rows whose twin ends elsewhere as a reader should see it (from
    :func:`outcome_counts`): "1 (regimes among them: 3d 1)", "not checked ..." where no row
    ran a twin (``--no-twin``), with how many did where only some did."""
    regimes = ", ".join(f"{k} {v}" for k, v in counts["undetermined_regimes"].items()) or "none"
    twinned, cases = counts["twinned"], counts["cases"]
    if twinned == 0:
        return "not checked (unknown): no case ran a twin (--no-twin)"
    text = f"{counts['undetermined']} (regimes among them: {regimes})"
    return text if twinned == cases else f"{text}, of the {twinned} of {cases} cases with a twin"


def unsteady_text(counts):
    """The count of rows still moving at their end as a reader should see it (from
    :func:`outcome_counts`): "2 (regimes among them: 3d 2)", or where rows do not record
    ``terminal_state``, "not recorded ..." with how many and the count among the rest."""
    regimes = ", ".join(f"{k} {v}" for k, v in counts["unsteady_regimes"].items()) or "none"
    if counts["unsteady"] is not None:
        return f"{counts['unsteady']} (regimes among them: {regimes})"
    missing, cases = counts["unsteady_not_recorded"], counts["cases"]
    text = (f"not recorded (unknown) for {missing} of {cases} cases: their rows have no "
            "terminal_state (written by a release before it existed)")
    if missing < cases:
        text += (f"; {counts['unsteady_recorded']} of the {cases - missing} that record it "
                 f"(regimes among them: {regimes})")
    return text


def stop_counts(stops):
    """The counts of a ``--seeds auto`` stop table (``storage.read_stop_table``) that ``loopsim
    sweep`` closes with: ``points``, ``reasons`` ({stop_reason: points}), ``seeds_min``,
    ``seeds_max`` (seeds per point)."""
    return dict(points=len(stops),
                reasons={str(k): int(v) for k, v in
                         sorted(stops["stop_reason"].value_counts().items())},
                seeds_min=int(stops["seeds"].min()), seeds_max=int(stops["seeds"].max()))


def cost(frame):
    """The total cost of a results table: ``cases``, ``wall_s`` (seconds of integration,
    summed over the rows), ``nfev`` and ``twin_nfev`` (right-hand-side evaluations of the
    runs and of their twins, summed)."""
    return dict(cases=len(frame), wall_s=float(frame["wall_s"].sum()),
                nfev=int(frame["nfev"].sum()),
                twin_nfev=int(frame["twin_nfev"].fillna(0).sum()) if "twin_nfev" in frame else 0)


def costliest(frame, count=10):
    """The ``count`` rows of a results table with the largest ``wall_s`` (their
    :data:`COST_COLUMNS`), costliest first."""
    shown = [c for c in COST_COLUMNS if c in frame]
    return frame.sort_values("wall_s", ascending=False, kind="stable")[shown].head(count)


# ---- convergence in distribution: two sweeps of the same cells ---------------------------
#: The verdicts of :func:`compare`.
SAME, DIFFERENT = "indistinguishable at this sample size", "different"


def _paired_cells(a, b, by):
    """The pairing columns (default: g0, theta0_deg and every input that varies within
    either table: a cell is never merged with another) and the [(key, rows_a, rows_b)] of
    the cells both tables hold."""
    if by is None:
        by = [c for c in CELL_INPUTS if c in ("g0", "theta0_deg") or any(
            c in t and t[c].nunique(dropna=False) > 1 for t in (a, b))]
    missing = [c for c in by if c not in a or c not in b]
    if missing:
        raise ValueError(f"no column(s) {missing} in both tables to pair the cells by "
                         "(an input varies within one table only: pass by=)")
    groups_b = dict(cell_groups(b, by))
    pairs = [(key, rows, groups_b[key]) for key, rows in cell_groups(a, by) if key in groups_b]
    if not pairs:
        raise ValueError(f"the two tables share no cell (by {by})")
    return by, pairs


def wasserstein_interval(x, y, resamples=BOOTSTRAP_RESAMPLES, seed=0, level=0.95):
    """(distance, low, high): the 1-Wasserstein distance between the finite values of x
    and y with a percentile-bootstrap interval (:func:`percentile_bootstrap`: each sample
    resampled on its own, seeded); NaN three times if either sample is empty."""
    from scipy.stats import wasserstein_distance

    x, y = np.asarray(x, float), np.asarray(y, float)
    x, y = x[np.isfinite(x)], y[np.isfinite(y)]
    if not (x.size and y.size):
        return float("nan"), float("nan"), float("nan")
    low, high, _ = percentile_bootstrap([x, y], wasserstein_distance, resamples, seed, level,
                                        vectorized=False)
    return float(wasserstein_distance(x, y)), low, high


def compare(a, b, by=None, alpha=0.05, seed=0, resamples=500):
    """Whether two results tables of the same cells differ in distribution, cell by cell.

    For each cell both tables hold (the same cells at, say, n = 24 and n = 32, or at two
    tolerances): two-sample Kolmogorov-Smirnov tests of the terminal tilt and aspect
    ratio, the tilt's 1-Wasserstein distance with a bootstrap interval, a chi-square test
    of the regime counts, and a verdict: "different" when any of the three p-values
    is below alpha / 3 (Bonferroni), else "indistinguishable at this sample size". The
    verdict rests on the p-values only. A distance is never negative, so its bootstrap
    interval lies above the distance of two samples of one distribution (a table
    compared with itself: 0 with an interval that excludes 0).

    Parameters
    ----------
    a, b : pandas.DataFrame
        Results tables (``loopsim.read_results``) with ``theta_final_deg``,
        ``aspect_ratio``, ``regime`` and the pairing columns.
    by : list of str or None, default None
        The columns that pair the cells; None: g0, theta0_deg and every input of
        ``CELL_INPUTS`` that varies within either table.
    alpha : float, default 0.05
        Significance level of the verdict (a probability, over the three tests).
    seed : int, default 0
        Seed of the bootstrap's generator.
    resamples : int, default 500
        Bootstrap resamples of the Wasserstein interval: fewer than the summaries'
        ``BOOTSTRAP_RESAMPLES``, because each resample recomputes a distance and the
        interval describes the distance's spread, not the verdict.

    Returns
    -------
    pandas.DataFrame
        One row per shared cell, with the columns of ``loopsim.columns.COMPARE_COLUMNS``:
        ``seeds_a``, ``seeds_b``, ``tilt_ks_p``, ``aspect_ks_p``, ``tilt_wasserstein``
        (degrees) and its interval, ``regime_p``, ``verdict``.
        ``table.attrs["loopsim_compare"]`` records the pairing and the bootstrap.

    Raises
    ------
    ValueError
        A pairing column is missing from either table, or the tables share no cell.

    Examples
    --------
    The same cell's seeds at two orders:

    >>> import loopsim
    >>> a = loopsim.sweep(40.0, 30.0, "runs/n6", n=6, t_end=0.5, seeds=4, twin=False)
    >>> b = loopsim.sweep(40.0, 30.0, "runs/n8", n=8, t_end=0.5, seeds=4, twin=False)
    >>> loopsim.compare(a, b)[["g0", "theta0_deg", "tilt_ks_p", "verdict"]]
         g0  theta0_deg  tilt_ks_p                                verdict
    0  40.0        30.0        1.0  indistinguishable at this sample size
    """
    from scipy.stats import chi2_contingency, ks_2samp

    by, pairs = _paired_cells(a, b, by)
    rows = []
    for key, rows_a, rows_b in pairs:
        out = dict(zip(by, key), seeds_a=len(rows_a), seeds_b=len(rows_b))
        for column, short in (("theta_final_deg", "tilt"), ("aspect_ratio", "aspect")):
            x, y = rows_a[column].to_numpy(float), rows_b[column].to_numpy(float)
            x, y = x[np.isfinite(x)], y[np.isfinite(y)]
            out[f"{short}_ks_p"] = float(ks_2samp(x, y).pvalue) if x.size and y.size else np.nan
        out["tilt_wasserstein"], out["tilt_wasserstein_low"], out["tilt_wasserstein_high"] = (
            wasserstein_interval(rows_a["theta_final_deg"], rows_b["theta_final_deg"],
                                 resamples, seed))
        counts = pd.crosstab(pd.concat([rows_a["regime"], rows_b["regime"]], ignore_index=True),
                             np.repeat([0, 1], [len(rows_a), len(rows_b)]))
        out["regime_p"] = (1.0 if counts.shape[0] < 2
                           else float(chi2_contingency(counts.to_numpy())[1]))
        p_values = [out["tilt_ks_p"], out["aspect_ks_p"], out["regime_p"]]
        out["verdict"] = DIFFERENT if np.nanmin(p_values) < alpha / 3 else SAME
        rows.append(out)
    table = pd.DataFrame(rows)
    table.attrs["loopsim_compare"] = dict(cells_by=by, alpha=alpha, bootstrap_seed=seed,
                                          bootstrap_resamples=resamples)
    return table
