"""Terminal outcomes: Figs. 7 (terminal q and tilt) and 8 (aspect ratio), and over seeds."""
import numpy as np
from matplotlib.ticker import MaxNLocator

from .linear import branch_lines
from .style import (
    ASPECT_LABEL, default_thresholds, new_figure, order_column, orders_text, q_lines,
    scatter_regimes, single_axes,
)


def _reference(ax, reference, xcol, ycol):
    if reference is not None and len(reference):
        ax.scatter(reference[xcol], reference[ycol], marker="D", s=26, facecolors="none",
                   edgecolors="k", linewidths=0.9, zorder=4,
                   label=f"{orders_text(reference)} (reference)")


def q_and_tilt(frame, thresholds=None, axes=None, reference=None):
    """Fig. 7.  Left: terminal q (= g0 sin θ_final / 3) against q0, with the thresholds
    (the paper's 14.56 and its empirical band 10.5-18.5; the full linearisation's 8.90
    and 10.65).  Right: θ_final against θ0 (stable shifted 1° left, in-plane 1° right, as
    in the paper).  ``reference``: an optional second table (for example resolved runs at
    higher n), drawn with black-edged diamonds."""
    fig, (left, right) = new_figure(axes, (1, 2), (10.0, 4.8))
    thresholds = thresholds or default_thresholds(
        int(frame[order_column(frame)].max()) if len(frame) else 16)
    q_max = float(max(frame["q0"].max(), frame["q_final"].max())) * 1.05 if len(frame) else 1.0
    left.plot([0, q_max], [0, q_max], color="0.8", lw=0.8, zorder=1)
    right.plot([0, 92], [0, 92], color="0.8", lw=0.8, zorder=1)
    q_lines(left, thresholds, vertical=False)
    scatter_regimes(left, frame, "q0", "q_final")
    scatter_regimes(right, frame, "theta0_deg", "theta_final_deg",
                    shift={"stable": -1.0, "in-plane": 1.0})
    for ax, xcol, ycol in ((left, "q0", "q_final"), (right, "theta0_deg", "theta_final_deg")):
        _reference(ax, reference, xcol, ycol)
    left.set(xlabel=r"initial $q_0 = g_0 \sin\theta_0 / 3$",
             ylabel=r"terminal $q = g_0 \sin\theta / 3$", xlim=(0, q_max), ylim=(0, q_max))
    right.set(xlabel=r"initial tilt $\theta_0$ (deg)", ylabel=r"terminal tilt $\theta$ (deg)",
              xlim=(0, 92), ylim=(0, 92))
    handles, labels = left.get_legend_handles_labels()
    fig.legend(handles, labels, fontsize=8, frameon=False, loc="outside lower center", ncol=3)
    fig.suptitle(f"initial against terminal state, {orders_text(frame)}", fontsize=10)
    return fig


def aspect_ratio(frame, branch=None, ax=None, reference=None, q_max=None):
    """Fig. 8: terminal aspect ratio (largest / middle covariance eigenvalue: the variance
    along the major principal axis over that along the minor one) against the terminal q,
    by regime.  ``branch``: a DataFrame with columns q, aspect_ratio, stable_in_plane,
    stable_out_of_plane (``stability.branch.steady_branch``): drawn solid where stable in
    and out of plane, dashed elsewhere.  ``reference``: an optional second table drawn
    with black-edged diamonds.  ``q_max``: right end of the q axis (the number of cases
    beyond it is written on the plot)."""
    fig, ax = single_axes(ax, (7.4, 4.4))
    ax.axhline(1.0, color="0.8", lw=0.8, zorder=1)
    scatter_regimes(ax, frame, "q_final", "aspect_ratio")
    _reference(ax, reference, "q_final", "aspect_ratio")
    if branch is not None and len(branch):
        branch_lines(ax, branch)
    ax.set_xlabel(r"terminal $q = g_0 \sin\theta / 3$")
    ax.set_ylabel("terminal " + ASPECT_LABEL)
    ax.set_title(f"terminal shape against terminal q, {orders_text(frame)}", fontsize=10)
    ax.set_ylim(bottom=0.9)
    ax.set_xlim(left=0)
    if q_max is not None:
        ax.set_xlim(0, q_max)
        beyond = int((frame["q_final"] > q_max).sum())
        if reference is not None and len(reference):
            beyond += int((reference["q_final"] > q_max).sum())
        if beyond:
            ax.text(0.98, 0.02, f"{beyond} cases with q > {q_max:g} not shown",
                    transform=ax.transAxes, ha="right", va="bottom", fontsize=8, color="0.3")
        visible = frame[frame["q_final"] <= q_max]["aspect_ratio"]
        if len(visible):
            ax.set_ylim(0.9, max(1.1, float(visible.max()) * 1.08))
    ax.legend(fontsize=8, frameon=False, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    return fig


def seed_distributions(frames, labels=None, axes=None, bins=12):
    """Terminal tilt and aspect ratio over seeds: one histogram per table (for example
    the same (g0, θ0) at n = 6 and n = 16), the initial tilt θ0 marked; one legend below
    the panels, the point (g0, θ0) in the title."""
    frames = list(frames)
    if not frames:
        raise ValueError("no tables to draw")
    labels = labels or [orders_text(f) for f in frames]
    fig, (left, right) = new_figure(axes, (1, 2), (9.0, 3.9))
    tilt_edges = np.linspace(0, 90, bins + 1)
    ar = np.concatenate([f["aspect_ratio"].to_numpy(float) for f in frames])
    ar_edges = np.linspace(min(1.0, ar.min()), max(ar.max(), 1.05), bins + 1)
    for i, (frame, label) in enumerate(zip(frames, labels)):
        kwargs = dict(histtype="step", lw=1.6, color=f"C{i}",
                      label=f"{label} ({len(frame)} seeds)")
        left.hist(frame["theta_final_deg"], bins=tilt_edges, **kwargs)
        right.hist(frame["aspect_ratio"], bins=ar_edges, **kwargs)
    theta0 = sorted(set(np.round(np.concatenate([f["theta0_deg"].to_numpy() for f in frames]), 6)))
    g0 = sorted(set(np.round(np.concatenate([f["g0"].to_numpy() for f in frames]), 6)))
    for value in theta0:
        left.axvline(value, color="0.3", ls="--", lw=1.0, label=f"initial tilt θ0 = {value:g}°")
    left.set(xlabel=r"terminal tilt $\theta$ (deg)", ylabel="seeds", xlim=(0, 90))
    right.set(xlabel="terminal " + ASPECT_LABEL, ylabel="seeds")
    for ax in (left, right):
        ax.set_ylim(0, ax.get_ylim()[1] * 1.05)
        ax.yaxis.set_major_locator(MaxNLocator(integer=True))
    handles, names = left.get_legend_handles_labels()
    fig.legend(handles, names, fontsize=8, frameon=False, loc="outside lower center",
               ncol=min(len(names), 3))
    fig.suptitle("terminal outcomes over seeds, g0 = " + ", ".join(f"{v:g}" for v in g0)
                 + ", θ0 = " + ", ".join(f"{v:g}°" for v in theta0), fontsize=10)
    return fig
