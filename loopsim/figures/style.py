"""Shared style and helpers of the figure modules: axes grids, curves, regime scatter, q lines.

Regime colours are :data:`REGIME_STYLE` (the paper's: stable dark purple, in-plane
green-blue, 3D yellow); cases not resolved at their n are drawn hollow, cases not
determined (a stricter twin ends elsewhere) ringed red.
"""
import os

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D

from .. import models, spectral
from ..stability import full_linear, paper

REGIME_STYLE = {
    "stable": dict(color="#3b0f70", marker="o", label="stable"),
    "in-plane": dict(color="#21918c", marker="s", label="in-plane"),
    "3d": dict(color="#f0c419", marker="^", label="3D"),
    "failed": dict(color="#d62728", marker="x", label="failed"),
}


def order_column(frame):
    """The column holding each row's truncation order: ``n_used`` (the order its terminal
    coefficients are at; with ``--n auto`` the highest reached) when present, else ``n``."""
    return "n_used" if "n_used" in frame and frame["n_used"].notna().all() else "n"


def orders_text(frame):
    """'n = 6' for a fixed-n table, 'n auto (n_used = 12, 16)' for ``--n auto`` rows."""
    column = order_column(frame)
    values = ", ".join(str(int(v)) for v in sorted(frame[column].unique()))
    config = (frame.attrs.get("loopsim", {}) or {}).get("sweep_config", {}) or {}
    auto = bool(config.get("n_auto")) or (column == "n_used" and bool((frame["n_used"] != frame["n"]).any()))
    return f"n auto (n_used = {values})" if auto else f"n = {values}"


def frame_model(frame):
    """The ``models.Model`` of a results table's rows (local for a table without the
    column); ValueError for a table mixing models (one diagram, one model)."""
    if "model" not in frame or not len(frame):
        return models.LOCAL
    pairs = {(m, None if m == "local" else float(e))
             for m, e in zip(frame["model"], frame["slenderness"])}
    if len(pairs) > 1:
        raise ValueError(f"the table mixes models {sorted(pairs, key=str)}: draw one at a time")
    return models.choose(*pairs.pop())


def model_text(model):
    """'' for the local model, ', nonlocal SBT, ε = 0.001' for the nonlocal one."""
    return "" if model.name == "local" else f", nonlocal SBT, ε = {model.slenderness:g}"


def mark_undetermined(ax, frame, xcol, ycol, size=22, shift=0.0):
    """Ring the rows whose outcome is not determined (``determined`` False: a twin at
    stricter tolerances ends elsewhere, ``loopsim.outcomes``) in red, one legend entry."""
    if "determined" not in frame:
        return
    rows = frame[frame["determined"].eq(False).to_numpy()]
    if len(rows):
        ax.scatter(rows[xcol] + shift, rows[ycol], s=3.2 * size, marker="o", facecolors="none",
                   edgecolors="#d62728", linewidths=0.9, zorder=4,
                   label="not determined (twin\nends elsewhere)")


#: The paper's empirical edges of the in-plane regime (§6, Figs. 5, 7 and 9), q = g0 sin θ0 / 3.
PAPER_BAND = (10.5, 18.5)


def save(fig, path, dpi=200):
    """Write ``fig`` to ``path`` (its directory made if absent; atomically: a failed write
    leaves no file) and close it."""
    from .. import storage

    try:
        storage.write_file_atomically(path, lambda tmp: fig.savefig(
            tmp, dpi=dpi, format=os.path.splitext(path)[1][1:] or None))
    finally:
        plt.close(fig)
    return path


#: Colour map of time in trajectories: light yellow (start) to dark purple (end), as the
#: paper's Fig. 6.
TIME_CMAP = "viridis_r"
#: Points per loop when drawing shapes.
CURVE_POINTS = 256
#: What ``aspect_ratio`` is (``loopsim.columns``): the ratio of the covariance's two largest
#: eigenvalues, the variances of the centreline along its major and minor principal axes
#: (the square of the ratio of the principal extents).
ASPECT_LABEL = "aspect ratio (variance along the\nmajor / minor principal axis)"


def new_figure(axes, shape, figsize, **kwargs):
    """(figure, flat list of axes): the given ones, or a new constrained-layout grid."""
    if axes is None:
        fig, axes = plt.subplots(*shape, figsize=figsize, constrained_layout=True, **kwargs)
    axes = list(np.ravel(axes))
    return axes[0].figure, axes


def single_axes(ax, figsize):
    """(figure, axes): ``ax`` and its figure, or a new figure with one axes."""
    if ax is None:
        fig, ax = plt.subplots(figsize=figsize, constrained_layout=True)
        return fig, ax
    return ax.figure, ax


def coefficients(row_x, n=None):
    """Coefficients (3, 2n+1) from a stored flat list (``x_final`` or a snapshot's ``x``)."""
    x = np.asarray(row_x, dtype=float)
    k = x.size // 3
    if n is not None and k != spectral.n_coeffs(int(n)):
        raise ValueError(f"{x.size} coefficients do not match n = {n}")
    return x.reshape(3, k)


def centred_curve(x, points=CURVE_POINTS):
    """Points (3, points + 1) of the closed curve x, centred on its centre of mass:
    only the mean coefficient a0 of each component is removed."""
    x = np.array(x, dtype=float)
    x[:, 0] = 0.0
    s = np.linspace(0.0, 2.0 * np.pi, points + 1)
    return spectral.evaluate(x, s)


def regime_style(regime):
    """The :data:`REGIME_STYLE` entry of a regime (that of "failed" for anything else)."""
    return REGIME_STYLE.get(regime, REGIME_STYLE["failed"])


def resolved_mask(frame):
    """Boolean array: the rows that are ``resolved`` (all, for a table without the column)."""
    if "resolved" in frame:
        return frame["resolved"].to_numpy(bool)
    return np.ones(len(frame), bool)


def regime_key(regimes, lw=2.0):
    """Legend handles: one coloured line per regime in ``regimes`` (in REGIME_STYLE order)."""
    return [Line2D([], [], color=style["color"], lw=lw, label=style["label"])
            for regime, style in REGIME_STYLE.items() if regime in set(regimes)]


def scatter_regimes(ax, frame, xcol, ycol, shift=None, size=20, label_suffix=""):
    """Scatter by regime, resolved filled and unresolved hollow, undetermined ringed red
    (:func:`mark_undetermined`); ``shift``: {regime: dx}."""
    resolved = resolved_mask(frame)
    shifted = frame.assign(**{xcol: frame[xcol] + frame["regime"].map(shift or {}).fillna(0.0)})
    mark_undetermined(ax, shifted, xcol, ycol, size)
    for regime, style in REGIME_STYLE.items():
        mask = (frame["regime"] == regime).to_numpy()
        dx = (shift or {}).get(regime, 0.0)
        for done in (True, False):
            rows = frame[mask & (resolved == done)]
            if not len(rows):
                continue
            x, y = rows[xcol] + dx, rows[ycol]
            if done or style["marker"] == "x":
                ax.scatter(x, y, s=size, marker=style["marker"], color=style["color"],
                           linewidths=1.0, label=style["label"] + label_suffix, zorder=3)
            else:
                ax.scatter(x, y, s=size, marker=style["marker"], facecolors="none",
                           edgecolors=style["color"], linewidths=1.0, zorder=3,
                           label=f"{style['label']}{label_suffix}, not resolved")


def default_thresholds(n=16):
    """q thresholds: the paper's operator and the full linearisation (in-plane, out-of-plane)."""
    return dict(paper=paper.critical_q(20), in_plane=full_linear.critical_q(max(n, 3), "in-plane"),
                out_of_plane=full_linear.critical_q(max(n, 3), "out-of-plane"))


def rest_window_for(frame):
    """The stable branch's window (``stability.rest_window.stability_losses``, computed once
    per machine and code version) for a local-model table, None for another model (its
    branch is not continued): what the phase diagrams take as ``rest_window``."""
    from ..stability import rest_window

    return rest_window.window_for(frame)


def rest_window_curve(ax, window, theta):
    """The window's upper edge in the (θ0, g0) plane, g0 = 3 q_loss / sin θ0 (its lower
    edge is the in-plane threshold's curve): cells above it start above their window."""
    loss = window.losses[0]
    kind = {"hopf": "Hopf"}.get(loss.kind, loss.kind)
    ax.plot(theta, 3 * loss.q / np.sin(np.radians(theta)), color="tab:green", lw=1.2,
            label=f"stable branch's upper edge\n({kind}, {loss.sector}), q = {loss.q:.3f}")


def q_lines(ax, thresholds, vertical=True, band=True):
    """The thresholds as lines at constant q (vertical or horizontal), with the paper's
    empirical in-plane band when ``band``."""
    line = ax.axvline if vertical else ax.axhline
    line(thresholds["paper"], color="k", lw=1.1,
         label=f"paper's linear stability, q = {thresholds['paper']:.2f}")
    line(thresholds["in_plane"], color="k", lw=1.0, ls="--",
         label=f"full linearisation, in-plane, q = {thresholds['in_plane']:.2f}")
    line(thresholds["out_of_plane"], color="k", lw=1.0, ls=":",
         label=f"full linearisation, out-of-plane, q = {thresholds['out_of_plane']:.2f}")
    if band:
        for i, q in enumerate(PAPER_BAND):
            line(q, color="0.55", lw=1.0, ls="-.",
                 label=f"paper's empirical in-plane band, q = {PAPER_BAND[0]:g}-{PAPER_BAND[1]:g}"
                 if i == 0 else None)


def merged_legend_entries(axes):
    """(handles, labels) of every labelled artist of ``axes``, one per label: markers by
    regime (REGIME_STYLE order, each regime's "not resolved" variant after it), then the
    rest in order of first appearance.  For one legend shared by several panels."""
    seen = {}
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels()):
            if label and not label.startswith("_"):
                seen.setdefault(label, handle)
    labels = list(seen)

    def rank(item):
        index, label = item
        for k, style in enumerate(REGIME_STYLE.values()):
            if label == style["label"] or label.startswith(style["label"] + ","):
                return (0, k, label != style["label"], index)
        return (1, 0, False, index)

    ordered = [label for _, label in sorted(enumerate(labels), key=rank)]
    return [seen[label] for label in ordered], ordered
