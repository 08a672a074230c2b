"""How long loops take to come to rest, and where they rest: the Kaplan–Meier survival of
"not yet at rest" per cell (``loopsim.survival``), terminal tilts against the stable
branch's tilt window (``loopsim.stability.rest_window``), and the paper's range as
regime probabilities and P(not at rest by t = 10) cell by cell."""
import matplotlib.pyplot as plt
import numpy as np

from .. import survival
from .distributions import regime_pies, threshold_curves
from .style import merged_legend_entries, single_axes

#: Line colours of successive cells (matplotlib's tab10 order).
CELL_COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown",
                "tab:pink", "tab:gray", "tab:olive", "tab:cyan")


def _cell_label(g0, theta0):
    return f"g0 = {g0:.4g}, θ0 = {theta0:.4g}°"


def survival_curves(frame, ax=None, horizon=survival.PAPER_HORIZON):
    """S(t), the share of a cell's loops not yet at rest at time t (Kaplan–Meier, with its
    95 % log-log band shaded), one step curve per (g0, θ0) cell of a results table, a
    tick at each run still moving at its t_end (censored), and the paper's horizon
    t = 10 dashed.  Cells as ``outcome_statistics.cell_columns`` defines them (cells of
    rows never tested for rest are left out).  Returns the figure."""
    fig, ax = single_axes(ax, (6.0, 4.0))
    from ..outcome_statistics import cell_columns, rows_tested

    t_last = float(frame["t_final"].max()) if len(frame) else horizon
    by = cell_columns(frame)
    cells = [(key, rows) for key, rows in frame.groupby(by, sort=True, dropna=False)
             if rows_tested(rows)]   # a --no-early-stop row was never tested for rest
    for colour, (key, rows) in zip(CELL_COLOURS * 10, cells):
        g0, theta0 = float(rows["g0"].iloc[0]), float(rows["theta0_deg"].iloc[0])
        times, at_rest = survival.settling_times(rows)
        curve = survival.survival_curve(times, at_rest)
        if len(curve):
            t = np.append(curve["t"].to_numpy(float), times.max())
            sf = np.append(curve["sf"].to_numpy(float), curve["sf"].iloc[-1])
            low = np.append(curve["sf_low"].to_numpy(float), curve["sf_low"].iloc[-1])
            high = np.append(curve["sf_high"].to_numpy(float), curve["sf_high"].iloc[-1])
        else:   # none came to rest: S = 1 up to the longest run
            t, sf = np.array([0.0, times.max() if times.size else 0.0]), np.ones(2)
            low = high = sf
        label = f"{_cell_label(g0, theta0)} ({int(at_rest.sum())} of {times.size} at rest)"
        ax.step(t, sf, where="post", color=colour, label=label)
        ax.fill_between(t, low, high, step="post", color=colour, alpha=0.15, linewidth=0)
        censored = times[~at_rest]
        if censored.size:
            ax.plot(censored, [sf[np.searchsorted(t, c, side="right") - 1] for c in censored],
                    "|", color=colour, markersize=10, markeredgewidth=1.5)
    ax.axvline(horizon, color="0.4", linestyle="--", linewidth=1)
    ax.text(horizon, 0.02, " the paper's horizon", color="0.4", fontsize=8, va="bottom")
    ax.set(xlabel="t (t_u)", ylabel="not yet at rest, S(t)", ylim=(0.0, 1.08),
           xlim=(0.0, max(t_last, horizon) * 1.02))
    ax.legend(fontsize=7, loc="upper right", frameon=True, framealpha=0.9)
    ax.set_title("Kaplan–Meier survival of “not yet at rest” (95 % band; | still moving at t_end)",
                 fontsize=9)
    return fig


def _pooled_curve(ax, times, at_rest, colour, name, horizon):
    """One pooled Kaplan–Meier step curve with its band, and its exponential tail from
    the horizon on with the rate's interval; the smallest S drawn (for the axis)."""
    curve = survival.survival_curve(times, at_rest)
    if not len(curve):
        return 1.0
    t = np.append(curve["t"].to_numpy(float), times.max())
    sf, low, high = (np.append(curve[c].to_numpy(float), curve[c].iloc[-1])
                     for c in ("sf", "sf_low", "sf_high"))
    shown = sf > 0   # log axis: S = 0 (all at rest) ends the curve
    ax.step(t[shown], sf[shown], where="post", color=colour,
            label=f"{name}: {int(at_rest.sum())} of {times.size} at rest")
    ax.fill_between(t[shown], low[shown], high[shown], step="post", color=colour,
                    alpha=0.15, linewidth=0)
    rate, rate_low, rate_high, events, _ = survival.escape_rate(times, at_rest, horizon)
    # S is a right-continuous step function from S(0) = 1: its value at the horizon
    s_h = float(sf[np.searchsorted(t, horizon, side="right") - 1]) if horizon < t[-1] \
        else np.nan
    if np.isfinite(rate) and s_h > 0:
        tail = np.linspace(horizon, t[-1], 50)
        for r, style, label in ((rate, "--", f"{name}: exp. tail, r = {rate:.2f} per t_u "
                                 f"({events} events)"),
                                (rate_low, ":", None), (rate_high, ":", None)):
            ax.plot(tail, s_h * np.exp(-r * (tail - horizon)), style, color=colour,
                    linewidth=1, label=label)
    return float(sf[shown].min())


def pooled_survival(frame, ax=None, horizon=survival.PAPER_HORIZON, groups=None):
    """Loops of ``frame`` pooled into Kaplan–Meier survivals of "not yet at rest" (95 %
    band), on a log axis, each with its exponential tail S(t) = S(t_h) exp(−r (t − t_h))
    from the paper's horizon t_h on, r the escape rate after t_h (dashed; its 95 %
    interval dotted; ``survival.escape_rate``): a straight line where the tail is
    memoryless.  ``groups``: {name: boolean mask over the rows}, one curve each (default:
    every loop, one curve).  Returns the figure."""
    fig, ax = single_axes(ax, (6.0, 4.0))
    groups = groups if groups is not None else {"all loops": np.ones(len(frame), bool)}
    lowest = 1.0
    for colour, (name, mask) in zip(CELL_COLOURS, groups.items()):
        times, at_rest = survival.settling_times(frame[np.asarray(mask, bool)])
        lowest = min(lowest, _pooled_curve(ax, times, at_rest, colour, name, horizon))
    ax.set_yscale("log")
    ax.set_ylim(max(0.5 * lowest, 1e-4), 1.3)
    ax.axvline(horizon, color="0.4", linestyle="--", linewidth=1)
    ax.text(horizon, ax.get_ylim()[0] * 1.3, " the paper's horizon", color="0.4", fontsize=8)
    ax.set(xlabel="t (t_u)", ylabel="not yet at rest, S(t)")
    ax.legend(fontsize=7, loc="upper right", frameon=True, framealpha=0.9)
    ax.set_title("loops pooled: survival of “not yet at rest” (95 % band)", fontsize=9)
    return fig


def rest_tilts(frame, window, ax=None):
    """Terminal tilts of the loops that came to rest, per cell (x: cell, y: tilt), over the
    stable branch's tilt window at each cell's g0 (shaded; below it loops rest as tilted
    circles); loops still moving at their t_end as open markers.  ``window``: a
    ``loopsim.stability.rest_window.RestWindow``.  Returns the figure."""
    cells = list(frame.groupby(["g0", "theta0_deg"], sort=True))
    fig, ax = single_axes(ax, (max(4.0, 1.2 * len(cells) + 2.0), 4.0))
    for i, ((g0, theta0), rows) in enumerate(cells):
        low, high = window.tilts(g0)
        if low == low:   # (NaN where g0 < 3 q_c: no branch, every rest a circle)
            ax.fill_between([i - 0.4, i + 0.4], low, high, color="tab:green", alpha=0.2,
                            linewidth=0, label="stable branch" if i == 0 else None)
        ax.plot([i - 0.4, i + 0.4], [theta0, theta0], color="0.3", linewidth=1,
                label="initial tilt θ0" if i == 0 else None)
        rested = rows["stop_reason"].eq("steady")
        jitter = np.linspace(-0.25, 0.25, max(1, len(rows)))[: len(rows)]
        ax.plot(i + jitter[rested.to_numpy()], rows.loc[rested, "theta_final_deg"], "o",
                color="tab:blue", markersize=4, label="at rest" if i == 0 else None)
        moving = rows["stop_reason"].eq("t_end")
        ax.plot(i + jitter[moving.to_numpy()], rows.loc[moving, "theta_final_deg"], "o",
                mfc="none", color="tab:red", markersize=4,
                label="still moving at t_end" if i == 0 else None)
    ax.set_xticks(range(len(cells)), [_cell_label(g, t).replace(", ", "\n") for (g, t), _ in cells],
                  fontsize=7)
    ax.set(ylabel="terminal tilt (deg)", ylim=(0.0, 90.0))
    ax.legend(fontsize=7, frameon=False, loc="upper left")
    ax.set_title(f"where loops rest: the stable branch's tilt window\n(q = g0 sin θ / 3 from "
                 f"{window.q_circle:.4f} to the first loss, {window.q_loss:.4f})", fontsize=9)
    return fig


def range_overview(cells, window=None):
    """The paper's (θ0, g0) grid cell by cell, from one row per cell (columns ``g0``,
    ``theta0_deg``, ``seeds``, ``t_max``, ``p_stable``, ``p_in_plane``, ``p_3d``,
    ``p_failed``, ``p_not_rest_t10``; ``scripts/range_overview.py`` writes such a table):
    left, the regime probabilities as pies; right, P(not at rest by t = 10), the share of
    loops still moving at the paper's horizon (numbers where above 0).  Cells run past
    t = 10 are ringed, cells not run crossed; both panels carry the thresholds and,
    with ``window`` (``loopsim.stability.rest_window.RestWindow``), the stable branch's
    upper edge: cells above it start above the tilts where a loop can rest.  Returns the
    figure."""
    fig, (pies, late) = plt.subplots(1, 2, figsize=(13.0, 5.6), sharey=True)
    known = cells[cells["seeds"] > 0]
    regime_pies(known, pies, size=110)
    moving = known["p_not_rest_t10"].to_numpy(float)
    points = late.scatter(known["theta0_deg"], known["g0"], c=moving, cmap="YlOrRd", vmin=0.0,
                          vmax=1.0, s=80, edgecolors="0.4", linewidths=0.4, zorder=3)
    fig.colorbar(points, ax=late, label="P(not at rest by t = 10) over seeds", pad=0.01)
    for (_, cell), share in zip(known.iterrows(), moving):
        if share > 0:
            late.annotate(f"{share:.2f}".lstrip("0"), (cell["theta0_deg"], cell["g0"]),
                          ha="center", va="center", fontsize=4.5, zorder=4,
                          color="white" if share > 0.6 else "black")
    longer, empty = known[known["t_max"] > survival.PAPER_HORIZON], cells[cells["seeds"] == 0]
    for ax in (pies, late):
        if len(longer):
            ax.scatter(longer["theta0_deg"], longer["g0"], s=170, facecolors="none",
                       edgecolors="k", linewidths=0.7, zorder=4,
                       label=f"run to rest (t_max = {longer['t_max'].max():g})")
        if len(empty):
            ax.scatter(empty["theta0_deg"], empty["g0"], marker="x", s=25, color="0.55",
                       zorder=3, label="not run yet")
        threshold_curves(ax, window)
        ax.set_ylim(0, 1.06 * cells["g0"].max())
    late.set_ylabel("")
    seeds = sorted(set(int(k) for k in known["seeds"]))
    pies.set_title("regime probabilities per cell" + (
        f" ({seeds[0]}-{seeds[-1]} seeds)" if seeds else ": no cell run"), fontsize=10)
    late.set_title("what the paper's horizon hides: loops not at rest by t = 10", fontsize=10)
    handles, labels = merged_legend_entries([pies, late])
    fig.legend(handles, labels, fontsize=7, frameon=False, loc="lower center", ncol=4)
    fig.subplots_adjust(left=0.06, right=0.97, top=0.94, bottom=0.2, wspace=0.06)
    return fig
