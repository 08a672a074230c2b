"""Figs. 5 and 9: phase diagrams of one or several sweeps (g0 against θ0 by regime)."""
import numpy as np

from ..stability import full_linear, paper
from .style import (
    PAPER_BAND, REGIME_STYLE, frame_model, mark_undetermined, merged_legend_entries, model_text,
    new_figure, order_column, orders_text, rest_window_curve, single_axes,
)


def phase_diagram(frame, ax=None, paper_band=False, rest_window=None):
    """g0 against θ0 coloured by regime (hollow: the case is not resolved at its n, see
    ``outcomes.Thresholds.resolved``; ringed red: not determined), with the curves g0 = 3 q_c / sin θ0 of the
    paper's linear stability (q_c = 14.561, wrong sign) and of the full linearisation of
    the circle at the sweep's largest truncation (``n_used`` for ``--n auto`` rows;
    in-plane q_c ≈ 8.90, out-of-plane ≈ 10.65), in the rows' model (nonlocal: its
    thresholds at θ0 = 90°, drawn as g0 = 3 q_c / sin θ0).
    ``paper_band``: also the paper's empirical in-plane band q = 10.5 and 18.5 (its Fig. 5).
    ``rest_window`` (``style.rest_window_for(frame)``): also the upper edge of the stable
    branch's tilt window, g0 = 3 q_loss / sin θ0 (its lower edge is the in-plane curve):
    the loops of cells above it start above their window and must turn their plane before
    they can rest."""
    fig, ax = single_axes(ax, (6.6, 4.0))
    q_paper = paper.critical_q(20)
    order = int(frame[order_column(frame)].max())
    model = frame_model(frame)
    resolved = frame["resolved"] if "resolved" in frame else np.ones(len(frame), bool)
    for regime, style in REGIME_STYLE.items():
        failed = style["marker"] == "x"  # a failed case is drawn whether resolved or not
        rows = frame[(frame["regime"] == regime) & (resolved | failed)]
        if len(rows):
            ax.scatter(rows["theta0_deg"], rows["g0"], s=22, linewidths=1.2, **style)
        rows = frame[(frame["regime"] == regime) & ~resolved]
        if len(rows) and style["marker"] != "x":  # not resolved at n: hollow markers
            ax.scatter(rows["theta0_deg"], rows["g0"], s=22, linewidths=1.0, marker=style["marker"],
                       facecolors="none", edgecolors=style["color"],
                       label=f"{style['label']}, not resolved at n")
    mark_undetermined(ax, frame, "theta0_deg", "g0")
    theta = np.linspace(1.0, 90.0, 300)
    ax.plot(theta, 3 * q_paper / np.sin(np.radians(theta)), "k-", lw=1.2,
            label=f"paper's linear\nstability, q = {q_paper:.3f}")
    for sector, style in (("in-plane", "--"), ("out-of-plane", ":")):
        q_sector = full_linear.critical_q(max(order, 3), sector, model=model)
        ax.plot(theta, 3 * q_sector / np.sin(np.radians(theta)), "k", ls=style, lw=1.2,
                label=f"full linearisation,\n{sector}, q = {q_sector:.3f}")
    if rest_window is not None:
        rest_window_curve(ax, rest_window, theta)
    if paper_band:
        for i, q_band in enumerate(PAPER_BAND):
            ax.plot(theta, 3 * q_band / np.sin(np.radians(theta)), color="0.55", ls="-.", lw=1.0,
                    label=f"paper's empirical in-plane\nband, q = {PAPER_BAND[0]:g}, {PAPER_BAND[1]:g}"
                    if i == 0 else None)
    ax.set_xlim(0, 92)
    ax.set_ylim(0, 1.05 * frame["g0"].max())
    ax.set_xlabel(r"initial tilt $\theta_0$ (deg)")
    ax.set_ylabel(r"$g_0$ (gravity / stiffness)")
    ax.set_title(f"sedimentation regimes, {orders_text(frame)}, t = {frame['t_end'].max():g}"
                 + ("" if model.name == "local" else f"\n{model_text(model)[2:]}"), fontsize=10)
    ax.legend(fontsize=8, frameon=False, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    return fig


def phase_diagrams(frames, axes=None):
    """Fig. 9: phase diagrams (:func:`phase_diagram` with the paper's band) of several
    sweeps side by side, one per frame (for example n = 4 and n = 8), with one legend
    holding every panel's entries: a marker drawn in one panel only is in it too, and
    each panel's full-linearisation curves (at that panel's n) are named by their n."""
    frames = list(frames)
    if not frames:
        raise ValueError("no sweeps to draw")
    fig, flat = new_figure(axes, (1, len(frames)), (5.2 * len(frames) + 2.2, 4.2), squeeze=False)
    panels = flat[: len(frames)]
    for frame, ax in zip(frames, panels):
        phase_diagram(frame, ax=ax, paper_band=True)
        order = int(frame[order_column(frame)].max())
        for line in ax.get_lines():
            label = line.get_label()
            if label.startswith("full linearisation,"):
                line.set_label(label.replace("full linearisation,",
                                             f"full linearisation at n = {order},", 1))
    handles, labels = merged_legend_entries(panels)
    for ax in panels:
        ax.get_legend().remove()
    panels[-1].legend(handles, labels, fontsize=8, frameon=False, loc="upper left",
                      bbox_to_anchor=(1.01, 1.0))
    return fig
