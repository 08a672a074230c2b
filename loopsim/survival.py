"""How long loops take to come to rest: settling times as censored data.

A run *comes to rest* at ``t_final`` when it stops early because it passed the steady
test (``stop_reason`` "steady": no invariant changed by more than ``steady_tol`` per
``steady_interval``; ``loopsim.integrators.control``), so its settling time is
observed, late by at most about one ``steady_interval``.  A run that reached its
``t_end`` without passing it is *censored* there: it was not at rest by ``t_end``,
and nothing is known after.  Failed runs carry no settling time and are left out
(counted apart).  Times are in t_u (``loopsim.defaults``).

With ``T_i`` the observed time of run i and ``d_i`` whether it came to rest, the
survival of "not yet at rest" is the Kaplan–Meier product

    S(t) = ∏_{t_j ≤ t} (1 − d_j / r_j)      (r_j: runs still observed just before t_j)

(``scipy.stats.ecdf`` on ``scipy.stats.CensoredData``), with the 95 % exponential
Greenwood ("log-log") band.  Per cell (``settling_statistics``):

* ``p_rest_t10``: P(at rest by the paper's horizon t = 10) = 1 − S(10), with its
  95 % interval: the Wilson interval where every run was observed to at least t = 10
  (no censoring before it: the estimate is then a binomial proportion), the KM band
  otherwise (NaN limits where the band is undefined, S(10) = 0 or 1); NaN where no run
  was observed to t = 10 and some were still moving at their end (not estimable);
* ``t_rest_median`` (the first t with S(t) ≤ 1/2: lifelines' convention; R's
  ``survfit`` takes the midpoint where S = 1/2 on a whole step) with the times where
  the band's limits cross 1/2 (Brookmeyer–Crowley; NaN: not within the runs), and
  ``t_rest_q95`` (the first t with S(t) ≤ 0.05): NaN where the curve does not reach
  that far;
* the escape rate after the horizon, from the tail t > t0 = 10 taken as exponential:
  λ = D / E, D the runs that came to rest after t0, E the total time observed after
  t0 (Σ max(0, T_i − t0)), with the exact Poisson interval
  [χ²_{0.025}(2D) / 2E, χ²_{0.975}(2D + 2) / 2E]; NaN where D < ``MIN_TAIL_EVENTS``
  (the upper limit alone says little then; ``escape_events`` and ``tail_time`` still
  say what the tail holds).

Whether the tail is exponential: ``window_escape_rates`` splits it at given times into
windows (a, b] and takes the same estimate in each (D_w runs at rest in it, E_w =
Σ max(0, min(T_i, b) − a)); ``one_rate_p_value`` tests one rate across the windows
by the likelihood ratio G = 2 Σ_w D_w ln(D_w / (E_w λ̂)), λ̂ = ΣD / ΣE, against χ² with
(windows − 1) degrees of freedom (given ΣD, the counts are multinomial over the windows
in proportion to E_w: the G-test of that).  A mixture of cells with different rates has
a falling rate, which this test can detect where the tail holds enough events.

A survival that falls to zero within the runs' horizon is a transient; one that levels
off at S > 0 with runs censored at a long t_end is a lasting motion (tumbling, or a slow
approach where the decay rate vanishes, as at the edges of the stable window) or a
transient longer than that horizon: ``survival_curve`` gives the curve and band,
``terminal_state`` and the ``late_*`` columns say which motion.
"""
import math
import warnings

import numpy as np
import pandas as pd
from scipy import stats

from .intervals import wilson_interval

#: The paper's horizon, t = 10 t_u: P(at rest by then), and the start of the tail.
PAPER_HORIZON = 10.0
#: Fewest runs coming to rest after the horizon for an escape rate.
MIN_TAIL_EVENTS = 3
#: Confidence level of every interval here.
LEVEL = 0.95
#: The columns ``settling_statistics`` returns, in order.
SETTLING_COLUMNS = ("rest_observed", "at_rest", "p_rest_t10", "p_rest_t10_low",
                    "p_rest_t10_high", "t_rest_median", "t_rest_median_low",
                    "t_rest_median_high", "t_rest_q95", "escape_events", "tail_time",
                    "escape_rate", "escape_rate_low", "escape_rate_high")


def settling_times(frame):
    """(times, at_rest) of the runs of ``frame`` that did not fail: ``t_final`` and
    whether it is a settling time (``stop_reason`` "steady") or a censoring time
    (reached ``t_end``).  Rows with another ``stop_reason`` (failures) or none are
    left out."""
    reason = frame["stop_reason"]
    times = frame["t_final"].to_numpy(float)
    keep = reason.isin(("steady", "t_end")).to_numpy(bool) & np.isfinite(times)
    return times[keep], reason.to_numpy(object)[keep] == "steady"


def _censored(times, at_rest):
    return stats.CensoredData(uncensored=times[at_rest], right=times[~at_rest])


def kaplan_meier(times, at_rest, level=LEVEL):
    """The Kaplan–Meier survival of "not yet at rest" (module docstring) and its
    log-log band, as three ``scipy.stats`` EmpiricalDistributionFunction objects
    (estimate, low, high); None if no run came to rest."""
    times, at_rest = np.asarray(times, float), np.asarray(at_rest, bool)
    if not at_rest.any():
        return None
    sf = stats.ecdf(_censored(times, at_rest)).sf
    with warnings.catch_warnings():
        # undefined where S is 0 or 1, as scipy warns: _band_at fills those places
        warnings.simplefilter("ignore", RuntimeWarning)
        band = sf.confidence_interval(level, method="log-log")
    return sf, band.low, band.high


def _band_at(curve, estimate, t):
    """The band's limit ``curve`` at times t: the log-log band is undefined where S is 0
    or 1; before the first settling (S = 1, nothing happened yet) it is 1, as R's
    ``survfit`` gives it, and after the last (S = 0) NaN."""
    values = np.asarray(curve.evaluate(t), float)
    before_first = np.asarray(estimate.evaluate(t), float) == 1.0
    return np.where(np.isfinite(values), values, np.where(before_first, 1.0, np.nan))


def survival_curve(times, at_rest, level=LEVEL):
    """S(t) as a step table: columns ``t`` (0, then every settling time), ``sf``,
    ``sf_low``, ``sf_high`` (the value from t on), and ``at_risk`` (runs still observed
    just before t).  Empty if no run came to rest."""
    times, at_rest = np.asarray(times, float), np.asarray(at_rest, bool)
    km = kaplan_meier(times, at_rest, level)
    if km is None:
        return pd.DataFrame(columns=["t", "sf", "sf_low", "sf_high", "at_risk"])
    sf, low, high = km
    t = np.concatenate([[0.0], np.unique(times[at_rest])])
    at_risk = np.array([int(np.sum(times >= s)) for s in t])
    return pd.DataFrame(dict(t=t, sf=sf.evaluate(t), sf_low=_band_at(low, sf, t),
                             sf_high=_band_at(high, sf, t), at_risk=at_risk))


def _first_at_or_below(curve_values, t, level):
    hit = np.nonzero(curve_values <= level)[0]
    return float(t[hit[0]]) if hit.size else math.nan


def escape_rate(times, at_rest, onset=PAPER_HORIZON, level=LEVEL):
    """(rate, low, high, events, exposure) of the exponential tail after ``onset``
    (module docstring); rate and limits NaN where events < MIN_TAIL_EVENTS."""
    times, at_rest = np.asarray(times, float), np.asarray(at_rest, bool)
    events = int(np.sum(at_rest & (times > onset)))
    exposure = float(np.sum(np.maximum(0.0, times - onset)))
    if events < MIN_TAIL_EVENTS or exposure <= 0.0:
        return math.nan, math.nan, math.nan, events, exposure
    alpha = 1.0 - level
    low = stats.chi2.ppf(alpha / 2, 2 * events) / (2 * exposure)
    high = stats.chi2.ppf(1 - alpha / 2, 2 * events + 2) / (2 * exposure)
    return events / exposure, float(low), float(high), events, exposure


def window_escape_rates(times, at_rest, edges, level=LEVEL):
    """The escape rate in each window (edges[i], edges[i + 1]] (module docstring): a
    DataFrame with ``start``, ``end``, ``events``, ``exposure`` (t_u), ``rate`` (per
    t_u) and its exact Poisson ``low`` and ``high`` (NaN where a window has no exposure;
    ``low`` 0 where it has no event)."""
    times, at_rest = np.asarray(times, float), np.asarray(at_rest, bool)
    alpha, out = 1.0 - level, []
    for start, end in zip(edges[:-1], edges[1:]):
        events = int(np.sum(at_rest & (times > start) & (times <= end)))
        exposure = float(np.sum(np.clip(times, start, end) - start))
        rate = low = high = math.nan
        if exposure > 0.0:
            rate = events / exposure
            low = stats.chi2.ppf(alpha / 2, 2 * events) / (2 * exposure) if events else 0.0
            high = stats.chi2.ppf(1 - alpha / 2, 2 * events + 2) / (2 * exposure)
        out.append(dict(start=float(start), end=float(end), events=events,
                        exposure=exposure, rate=rate, low=float(low), high=float(high)))
    return pd.DataFrame(out)


def one_rate_p_value(events, exposures):
    """P-value of one escape rate across windows with ``events`` runs at rest in
    ``exposures`` t_u each (the likelihood-ratio G-test, module docstring); NaN with
    fewer than two windows with exposure or no event at all."""
    events, exposures = np.asarray(events, float), np.asarray(exposures, float)
    keep = exposures > 0.0
    events, exposures = events[keep], exposures[keep]
    if events.size < 2 or events.sum() == 0:
        return math.nan
    expected = exposures * events.sum() / exposures.sum()
    hit = events > 0
    g = 2.0 * float(np.sum(events[hit] * np.log(events[hit] / expected[hit])))
    return float(stats.chi2.sf(g, events.size - 1))


def settling_statistics(frame, horizon=PAPER_HORIZON, level=LEVEL):
    """The settling statistics of one cell's rows (``SETTLING_COLUMNS``, module
    docstring): ``rest_observed`` runs (not failed), ``at_rest`` of them came to rest,
    P(at rest by ``horizon``) with its interval, the median settling time with its
    interval, the time by which 95 % rest, and the escape rate after ``horizon``."""
    times, at_rest = settling_times(frame)
    out = dict.fromkeys(SETTLING_COLUMNS, math.nan)
    out.update(rest_observed=int(times.size), at_rest=int(at_rest.sum()))
    if not times.size:
        out.update(escape_events=0, tail_time=0.0)
        return out
    rested_by = int(np.sum(at_rest & (times <= horizon)))
    if np.all(at_rest & (times <= horizon) | (times >= horizon)):
        out["p_rest_t10"] = rested_by / times.size
        out["p_rest_t10_low"], out["p_rest_t10_high"] = wilson_interval(rested_by, times.size,
                                                                        level)
    km = kaplan_meier(times, at_rest, level)
    if km is not None:
        sf, low, high = km
        grid = np.unique(times[at_rest])
        estimate = sf.evaluate(grid)
        if math.isnan(out["p_rest_t10"]) and times.max() >= horizon:
            # censored before the horizon, some run observed past it: Kaplan-Meier
            s10 = float(sf.evaluate(horizon))
            out["p_rest_t10"] = 1.0 - s10
            if 0.0 < s10 < 1.0:
                out["p_rest_t10_low"] = 1.0 - float(high.evaluate(horizon))
                out["p_rest_t10_high"] = 1.0 - float(low.evaluate(horizon))
        out["t_rest_median"] = _first_at_or_below(estimate, grid, 0.5)
        out["t_rest_median_low"] = _first_at_or_below(_band_at(low, sf, grid), grid, 0.5)
        out["t_rest_median_high"] = _first_at_or_below(_band_at(high, sf, grid), grid, 0.5)
        out["t_rest_q95"] = _first_at_or_below(estimate, grid, 0.05)
        if math.isnan(out["p_rest_t10"]) and estimate[-1] == 0.0:
            out["p_rest_t10"] = 1.0   # every run came to rest, all before the horizon
    elif math.isnan(out["p_rest_t10"]) and times.max() >= horizon:
        out["p_rest_t10"] = 0.0       # none came to rest, some observed past the horizon
    (out["escape_rate"], out["escape_rate_low"], out["escape_rate_high"],
     out["escape_events"], out["tail_time"]) = escape_rate(times, at_rest, horizon, level)
    return out


def window_counts(frame, window):
    """``rest_inside``, ``rest_below``, ``rest_outside``: the rows of ``frame`` that came to
    rest (``stop_reason`` steady), by where their terminal tilt lies in the stable
    branch's tilt window at their g0 (``window``: a
    ``loopsim.stability.rest_window.RestWindow``, its ``classify`` and ``CLASSES``)."""
    rested = frame[frame["stop_reason"].eq("steady")]
    where = [window.classify(theta, g0)
             for theta, g0 in zip(rested["theta_final_deg"], rested["g0"])]
    return {f"rest_{name}": int(sum(w == name for w in where)) for name in window.CLASSES}
