"""Settling times as censored data (loopsim.survival): the Kaplan-Meier estimate against
a textbook table and a plain-NumPy product-limit twin, the escape rate's Poisson interval
against Garwood's table, and the per-cell statistics on fabricated cells."""
import math

import numpy as np
import pandas as pd
import pytest

from scipy import stats

from loopsim import outcome_statistics, survival


def product_limit(times, at_rest, t):
    """Plain product-limit estimate S(t) = prod over event times t_j <= t of (1 - d_j / r_j)."""
    times, at_rest = np.asarray(times, float), np.asarray(at_rest, bool)
    s = 1.0
    for tj in np.unique(times[at_rest]):
        if tj > t:
            break
        d = np.sum((times == tj) & at_rest)
        r = np.sum(times >= tj)
        s *= 1.0 - d / r
    return s


# Freireich et al. (1963), 6-MP arm (Klein & Moeschberger, Survival Analysis, table 4.1A):
# remission times in weeks, + marks a censored time.
SIX_MP = "6 6 6 6+ 7 9+ 10 10+ 11+ 13 16 17+ 19+ 20+ 22 23 25+ 32+ 32+ 34+ 35+".split()
SIX_MP_TIMES = np.array([float(v.rstrip("+")) for v in SIX_MP])
SIX_MP_EVENT = np.array([not v.endswith("+") for v in SIX_MP])
#: the book's Kaplan-Meier column at each event time, and its 95 % log-log limits (the
#: exponential Greenwood band, as R's survfit(conf.type = "log-log") prints it)
SIX_MP_KM = {6: 0.857, 7: 0.807, 10: 0.753, 13: 0.690, 16: 0.627, 22: 0.538, 23: 0.448}
SIX_MP_LOGLOG = {6: (0.620, 0.952), 7: (0.563, 0.923), 10: (0.503, 0.889),
                 13: (0.432, 0.849), 16: (0.368, 0.805), 22: (0.268, 0.747),
                 23: (0.188, 0.680)}


def test_kaplan_meier_reproduces_the_textbook_table():
    sf, low, high = survival.kaplan_meier(SIX_MP_TIMES, SIX_MP_EVENT)
    for t, expected in SIX_MP_KM.items():
        assert sf.evaluate(t) == pytest.approx(expected, abs=5e-4)
        assert (low.evaluate(t), high.evaluate(t)) == pytest.approx(SIX_MP_LOGLOG[t], abs=5e-4)
    # the median 23 weeks, its interval [13, not reached] (R: 23, 13, NA)
    frame = cell(SIX_MP_TIMES, np.where(SIX_MP_EVENT, "steady", "t_end"))
    out = survival.settling_statistics(frame)
    assert (out["t_rest_median"], out["t_rest_median_low"]) == (23.0, 13.0)
    assert math.isnan(out["t_rest_median_high"])
    curve = survival.survival_curve(SIX_MP_TIMES, SIX_MP_EVENT)
    assert list(curve["t"]) == [0.0, 6, 7, 10, 13, 16, 22, 23]
    assert list(curve["at_risk"]) == [21, 21, 17, 15, 12, 11, 7, 6]


@pytest.mark.parametrize("seed", range(5))
def test_kaplan_meier_matches_a_plain_product_limit(seed):
    rng = np.random.default_rng(seed)
    times = np.round(rng.exponential(8.0, 40), 1)       # rounded: ties happen
    censor = rng.uniform(5.0, 30.0, 40)
    at_rest = times <= censor
    observed = np.minimum(times, censor)
    sf, _, _ = survival.kaplan_meier(observed, at_rest)
    for t in np.linspace(0.0, 35.0, 71):
        assert sf.evaluate(t) == pytest.approx(product_limit(observed, at_rest, t), abs=1e-12)


def test_escape_rate_uses_the_exact_poisson_interval():
    # three runs come to rest after t = 10, at 12, 14, 16; two are censored at 20: the
    # exposure after 10 is 2 + 4 + 6 + 10 + 10 = 32; Garwood's 95 % interval for a
    # Poisson count of 3 is [0.6187, 8.7673]
    times = np.array([5.0, 12.0, 14.0, 16.0, 20.0, 20.0])
    at_rest = np.array([True, True, True, True, False, False])
    rate, low, high, events, exposure = survival.escape_rate(times, at_rest)
    assert (events, exposure) == (3, 32.0)
    assert rate == pytest.approx(3 / 32)
    assert low == pytest.approx(0.6187 / 32, rel=1e-3)
    assert high == pytest.approx(8.7673 / 32, rel=1e-3)
    # two events: too few for a rate, the tail still described
    rate, low, high, events, exposure = survival.escape_rate(times[:3], at_rest[:3])
    assert math.isnan(rate) and math.isnan(high) and events == 2


def test_escape_rate_estimates_a_known_exponential_tail():
    rng = np.random.default_rng(1)
    times = 10.0 + rng.exponential(1 / 0.2, 4000)        # rate 0.2 after t = 10
    at_rest = times <= 40.0
    rate, low, high, _, _ = survival.escape_rate(np.minimum(times, 40.0), at_rest)
    assert low < 0.2 < high and high - low < 0.03


def cell(times, reasons, g0=350.0, theta=18.0, tilts=None):
    """A fabricated cell: one row per run."""
    k = len(times)
    return pd.DataFrame(dict(
        g0=g0, theta0_deg=theta, seed=range(k), t_final=times, t_end=40.0, stop_reason=reasons,
        regime="3d", resolved=True, determined=pd.NA, twin_nfev=0, nfev=1, wall_s=1.0,
        theta_final_deg=tilts if tilts is not None else [10.0] * k, aspect_ratio=2.0,
        q_final=1.0))


def test_settling_statistics_of_a_cell():
    # the eight independent runs at (350, 18 deg) of issue 53, all at rest by t = 30,
    # and two failures, which carry no time
    times = [4.8, 5.5, 6.4, 7.6, 9.4, 9.9, 16.4, 18.4, 3.0, 2.0]
    reasons = ["steady"] * 8 + ["nan in the state", "step size underflow"]
    out = survival.settling_statistics(cell(times, reasons))
    assert (out["rest_observed"], out["at_rest"]) == (8, 8)
    assert out["p_rest_t10"] == 6 / 8                     # binomial: all observed past 10
    assert (out["p_rest_t10_low"], out["p_rest_t10_high"]) == pytest.approx(
        outcome_statistics.wilson_interval(6, 8))
    assert out["t_rest_median"] == 7.6                    # S(7.6) = 4/8
    assert out["t_rest_q95"] == 18.4
    assert out["t_rest_median_low"] <= 7.6 <= out["t_rest_median_high"]
    assert out["escape_events"] == 2 and math.isnan(out["escape_rate"])
    assert out["tail_time"] == pytest.approx(6.4 + 8.4)


def test_censoring_before_the_horizon_uses_kaplan_meier():
    # censored at t_end = 5 and 8 (runs with a short t_end): P(at rest by 10) from the
    # product limit, not the plain share
    times = [2.0, 5.0, 6.0, 8.0, 12.0, 12.0]
    reasons = ["steady", "t_end", "steady", "t_end", "t_end", "t_end"]
    out = survival.settling_statistics(cell(times, reasons))
    expected = 1.0 - product_limit(times, [True, False, True, False, False, False], 10.0)
    assert out["p_rest_t10"] == pytest.approx(expected)
    assert out["p_rest_t10_low"] <= expected <= out["p_rest_t10_high"]
    assert math.isnan(out["t_rest_median"])               # S stays above 1/2


def test_what_cannot_be_estimated_is_nan():
    # every run stopped before t = 10, some still moving: P(at rest by 10) is not known
    out = survival.settling_statistics(cell([2.0, 8.0, 8.0], ["steady", "t_end", "t_end"]))
    assert math.isnan(out["p_rest_t10"]) and out["at_rest"] == 1
    # all at rest before a short t_end: P = 1
    out = survival.settling_statistics(cell([2.0, 3.0], ["steady", "steady"]))
    assert out["p_rest_t10"] == 1.0
    # censored before 10, nobody at rest by 10 (S(10) = 1): no degenerate [0, 0] interval
    out = survival.settling_statistics(cell([5.0, 12.0, 14.0, 20.0],
                                            ["t_end", "steady", "steady", "t_end"]))
    assert out["p_rest_t10"] == 0.0 and math.isnan(out["p_rest_t10_low"])
    # a NaN time is left out, not a crash
    out = survival.settling_statistics(cell([4.0, float("nan"), 12.0],
                                            ["steady", "steady", "t_end"]))
    assert out["rest_observed"] == 2 and out["p_rest_t10"] == 0.5


def test_summarize_adds_the_settling_columns_only_where_rows_were_tested():
    frame = cell([4.0, 10.0, 10.0, 6.0], ["steady", "t_end", "t_end", "steady"])
    table = outcome_statistics.summarize(frame)
    assert table.loc[0, "at_rest"] == 2 and table.loc[0, "p_rest_t10"] == 0.5
    frame.attrs["loopsim"] = {"sweep_config": {"early_stop": False}}
    untested = outcome_statistics.summarize(frame)
    assert "p_rest_t10" not in untested or untested["p_rest_t10"].isna().all()


def test_survival_figure_and_report_section():
    import matplotlib

    matplotlib.use("Agg")
    from loopsim import figures, sweep_report
    from loopsim.stability.rest_window import RestWindow, StabilityLoss

    frame = pd.concat([
        cell([4.8, 5.5, 16.4, 40.0], ["steady", "steady", "steady", "t_end"], g0=350.0,
             tilts=[15.0, 12.0, 3.0, 60.0]),
        cell([3.0, 9.0, 10.0], ["steady", "steady", "t_end"], g0=325.7)], ignore_index=True)
    fig = figures.survival_curves(frame)
    ax = fig.axes[0]
    labels = [text.get_text() for text in ax.get_legend().get_texts()]
    assert labels == ["g0 = 325.7, θ0 = 18° (2 of 3 at rest)",
                      "g0 = 350, θ0 = 18° (3 of 4 at rest)"]
    # the 350 curve ends at the censored run's S = 1/4 (three of four came to rest)
    steps = [line for line in ax.get_lines() if line.get_label().startswith("g0 = 350")][0]
    assert steps.get_ydata()[-1] == pytest.approx(0.25)
    window = RestWindow(n=16, w=10.0, q_circle=8.9, losses=(
        StabilityLoss(q=37.55, kind="hopf", sector="out-of-plane", frequency=22.0),))
    assert survival.window_counts(frame[frame.g0 == 350.0], window) == dict(
        rest_inside=2, rest_below=1, rest_outside=0)
    figures.rest_tilts(frame, window)
    cells = outcome_statistics.summarize(frame, rest_window=window)
    assert list(cells["rest_inside"]) == [2, 2] and list(cells["rest_below"]) == [0, 1]
    html = sweep_report.settling_section(frame, cells)
    assert "<h2>Settling</h2>" in html and "data:image/png" in html


def test_pooled_survival_draws_the_exponential_tail_from_the_horizon():
    """Eight loops over two cells: four rest before t = 10, three after (t = 12, 14, 16),
    one is censored at 40. Pooled, S(10) = 1/2, S ends at 1/8, and the escape rate after
    10 is 3 events over 2 + 4 + 6 + 30 = 42 t_u of exposure."""
    import matplotlib

    matplotlib.use("Agg")
    from loopsim import figures

    frame = pd.concat([cell([2.0, 4.0, 12.0, 40.0], ["steady"] * 3 + ["t_end"], g0=350.0),
                       cell([6.0, 8.0, 14.0, 16.0], ["steady"] * 4, g0=325.7)],
                      ignore_index=True)
    ax = figures.pooled_survival(frame).axes[0]
    lines = {line.get_label(): line for line in ax.get_lines()}
    steps = lines["all loops: 7 of 8 at rest"]
    assert steps.get_ydata()[-1] == pytest.approx(1 / 8)
    tail = lines["all loops: exp. tail, r = 0.07 per t_u (3 events)"]
    t, s = tail.get_xdata(), tail.get_ydata()
    assert t[0] == 10.0 and s[0] == pytest.approx(0.5)
    assert s[-1] == pytest.approx(0.5 * np.exp(-3 / 42 * (t[-1] - 10.0)))
    assert ax.get_yscale() == "log"
    # one curve per group: the cell at 350 alone (3 of 4 at rest, S ends at 1/4)
    ax = figures.pooled_survival(frame, groups={"at 350": frame["g0"].eq(350.0)}).axes[0]
    lines = {line.get_label(): line for line in ax.get_lines()}
    assert lines["at 350: 3 of 4 at rest"].get_ydata()[-1] == pytest.approx(1 / 4)


def test_window_escape_rates_count_events_and_time_at_risk_per_window():
    # runs at rest at 12, 14, 16 and 30; one censored at 40; one at rest before 10
    times = [5.0, 12.0, 14.0, 16.0, 30.0, 40.0]
    at_rest = [True, True, True, True, True, False]
    table = survival.window_escape_rates(times, at_rest, [10.0, 15.0, 20.0, 40.0])
    # exposure in (10, 15]: 2 + 4*5 (the runs ending at 14, 16, 30, 40 and 12)
    assert list(table["events"]) == [2, 1, 1]
    assert table["exposure"].tolist() == pytest.approx([2 + 4 + 5 + 5 + 5, 1 + 5 + 5,
                                                        10 + 20])
    # the windows' events and exposure add up to the tail after 10 (escape_rate)
    rate, low, high, events, exposure = survival.escape_rate(times, at_rest, 10.0)
    assert table["events"].sum() == events and table["exposure"].sum() == pytest.approx(exposure)
    first = table.iloc[0]
    assert first["low"] == pytest.approx(stats.chi2.ppf(0.025, 4) / (2 * 21.0))
    assert first["high"] == pytest.approx(stats.chi2.ppf(0.975, 6) / (2 * 21.0))


def test_one_rate_p_value_is_the_multinomial_g_test():
    """Given the total, the events fall into the windows in proportion to their exposure
    under one rate: the same statistic as scipy's G-test of those counts."""
    events, exposures = np.array([30, 12, 3]), np.array([100.0, 60.0, 40.0])
    expected = events.sum() * exposures / exposures.sum()
    g, p = stats.power_divergence(events, expected, lambda_="log-likelihood")
    assert survival.one_rate_p_value(events, exposures) == pytest.approx(p)
    # the same rate in every window: nothing against it
    assert survival.one_rate_p_value([10, 5], [20.0, 10.0]) == pytest.approx(1.0)
    # a falling rate (a mixture of fast and slow cells) with enough events is found
    assert survival.one_rate_p_value([60, 10], [100.0, 100.0]) < 1e-6
    assert math.isnan(survival.one_rate_p_value([0, 0], [1.0, 1.0]))
