"""Outcomes over seeds as distributions: regime probabilities per cell, terminal tilt and
aspect ratio with their medians and intervals (tables of ``loopsim.summarize``)."""
import math

import matplotlib.pyplot as plt
import numpy as np

from ..stability import branch as steady, full_linear
from .linear import branch_lines
from .style import REGIME_STYLE, frame_model, rest_window_curve, save, single_axes

#: Where the steady branch drawn under a distribution summary ends, at most (its cost
#: grows with it: about 25 s to q = 25 at n = 12 on one core).
BRANCH_Q_MAX = 25.0


def wedge_marker(start, stop, points=24):
    """A pie wedge from angle ``start`` to ``stop`` (radians, counter-clockwise) as a
    scatter marker, and the factor its size must be scaled by: matplotlib rescales a
    marker's vertices to its largest coordinate, so a narrow wedge would grow."""
    angles = np.linspace(start, stop, max(2, int(points * (stop - start) / np.pi) + 2))
    verts = np.vstack([[0.0, 0.0], np.column_stack([np.cos(angles), np.sin(angles)]),
                       [0.0, 0.0]])
    return verts, float(np.abs(verts).max()) ** 2


def regime_pies(cells, ax, size=150):
    """Each cell of a summary table at (θ0, g0) as a pie of its regime probabilities
    (``p_stable``, ``p_in_plane``, ``p_3d``, ``p_failed``), clockwise from the top, in
    the regime colours of :data:`REGIME_STYLE`."""
    reached = set()
    for _, cell in cells.iterrows():
        start = np.pi / 2
        for regime, style in REGIME_STYLE.items():
            share = float(cell.get(f"p_{regime.replace('-', '_')}", 0.0) or 0.0)
            if share <= 0.0:
                continue
            stop = start - 2 * np.pi * share
            verts, scale = wedge_marker(stop, start)
            ax.scatter([cell["theta0_deg"]], [cell["g0"]], marker=verts, s=size * scale,
                       color=style["color"], edgecolors="none", zorder=3)
            reached.add(regime)
            start = stop
    for regime in (r for r in REGIME_STYLE if r in reached):  # legend entries: whole discs
        ax.scatter([], [], marker="o", s=size / 2, color=REGIME_STYLE[regime]["color"],
                   label=REGIME_STYLE[regime]["label"])


def check_one_cell_per_point(cells):
    """ValueError naming the first (g0, θ0) that holds several cells of a summary table
    (they differ in another input, say the model or rtol): a diagram over (θ0, g0) would
    draw them on top of each other.  Returns ``cells``."""
    repeated = cells[cells.duplicated(["g0", "theta0_deg"], keep=False)]
    if len(repeated):
        first = repeated.iloc[0]
        others = [c for c in cells.attrs.get("loopsim_summary", {}).get("cells_by", [])
                  if c not in ("g0", "theta0_deg")]
        count = int(((cells["g0"] == first["g0"])
                     & (cells["theta0_deg"] == first["theta0_deg"])).sum())
        raise ValueError(f"the summary has {count} cells at g0 = {first['g0']:g}, theta0 = {first['theta0_deg']:g} "
                         f"(they differ in {', '.join(others) or 'another input'}): one "
                         "diagram draws one cell per point; filter the rows and draw each apart")
    return cells


def probability_phase_diagram(cells, frame=None, ax=None, style="pie", rest_window=None):
    """The phase diagram read as probabilities: each cell of a summary table
    (``loopsim.summarize``) at (θ0, g0) as a pie of its regime probabilities
    (``style="pie"``, :func:`regime_pies`) or coloured by its probability of ending 3D
    (``style="colour"``, labelled with P(in-plane) when it is neither 0 nor 1); ringed
    red where a seed's twin ended elsewhere (not determined; seeds run without a twin
    are not counted), marked by a black triangle where any seed had
    not reached a steady state at ``t_end`` (its tilt is then a snapshot: only when some
    run of the table did stop early, so not for ``--no-early-stop``), with P(not at rest
    by t = 10) beside it where the table has ``p_rest_t10``; with the full
    linearisation's thresholds (``q_c`` at n = 16).  With ``rest_window``
    (``loopsim.stability.rest_window.RestWindow``) also the upper edge of the stable
    branch's window, q = q_loss: the in-plane threshold q_c is its lower edge, so a cell
    between the two curves starts inside its window, one above the upper curve above it
    (it must turn its plane before it can rest)."""
    if style not in ("pie", "colour"):
        raise ValueError(f"style must be 'pie' or 'colour', got {style!r}")
    check_one_cell_per_point(cells)
    fig, ax = single_axes(ax, (6.8, 4.0))
    if style == "pie":
        regime_pies(cells, ax)
    else:
        points = ax.scatter(cells["theta0_deg"], cells["g0"], c=cells["p_3d"],
                            cmap="viridis", vmin=0.0, vmax=1.0, s=60, edgecolors="k",
                            linewidths=0.4, zorder=3)
        fig.colorbar(points, ax=ax, label="P(3D) over seeds")
        for _, cell in cells[(cells["p_in_plane"] > 0) & (cells["p_in_plane"] < 1)].iterrows():
            ax.annotate(f"{cell['p_in_plane']:.2f}", (cell["theta0_deg"], cell["g0"]),
                        textcoords="offset points", xytext=(0, 7), ha="center", fontsize=6)
    known = cells["twinned"] if "twinned" in cells else cells["seeds"]  # (older tables)
    mixed = cells[(cells["determined"] < known).fillna(False).astype(bool)]
    # (ringed where a twin ended elsewhere; rows without a twin are unknown, not ringed)
    if len(mixed):
        ax.scatter(mixed["theta0_deg"], mixed["g0"], s=230 if style == "pie" else 150,
                   facecolors="none", edgecolors="#d62728", linewidths=0.9, zorder=4,
                   label="some seeds not determined")
    if "steady" in cells and cells["steady"].sum() > 0:
        unsteady = cells[(cells["steady"] < cells["seeds"]).fillna(False).astype(bool)]
        # (a cell whose steady is unknown, <NA>: never tested, is not marked)
        if len(unsteady):
            ax.scatter(unsteady["theta0_deg"] + 2.2, unsteady["g0"] + 0.035 * cells["g0"].max(),
                       marker="v", s=14, color="k", zorder=5,
                       label="some seeds not steady at t_end" + (
                           " (number: P(not at rest by t = 10))" if "p_rest_t10" in cells
                           else ""))
            if "p_rest_t10" in cells:
                for _, cell in unsteady.iterrows():
                    ax.annotate(f"{1.0 - cell['p_rest_t10']:.2f}",
                                (cell["theta0_deg"] + 3.2, cell["g0"] + 0.035 * cells["g0"].max()),
                                fontsize=5, va="center", zorder=5)
    threshold_curves(ax, rest_window)
    ax.set_ylim(0, 1.08 * cells["g0"].max())
    seeds = sorted(set(int(k) for k in cells["seeds"]))
    count = str(seeds[0]) if len(seeds) == 1 else f"{seeds[0]}-{seeds[-1]}"
    ax.set_title(f"regime probabilities per cell over {count} seeds" if style == "pie" else
                 f"P(3D) per cell over {count} seeds (numbers: P(in-plane))", fontsize=10)
    ax.legend(fontsize=7, frameon=False, loc="upper center", bbox_to_anchor=(0.5, -0.14),
              ncol=3)
    return fig


def threshold_curves(ax, rest_window=None):
    """The full linearisation's thresholds (n = 16) as curves g0 = 3 q_c / sin θ0 over the
    (θ0, g0) plane, with ``rest_window``'s upper edge where given; the axes' θ0 range
    and labels."""
    theta = np.linspace(1.0, 90.0, 300)
    for sector, line in (("in-plane", "--"), ("out-of-plane", ":")):
        q_sector = full_linear.critical_q(16, sector)
        ax.plot(theta, 3 * q_sector / np.sin(np.radians(theta)), "k", ls=line, lw=1.0,
                label=f"{sector} threshold, q = {q_sector:.3f}")
    if rest_window is not None:
        rest_window_curve(ax, rest_window, theta)
    ax.set_xlim(0, 92)
    ax.set_xlabel(r"initial tilt $\theta_0$ (deg)")
    ax.set_ylabel(r"$g_0$ (gravity / stiffness)")


def tilt_distribution(cells, frame=None, ax=None):
    """Terminal tilt against q0 as distributions (the distributional form of the paper's
    Fig. 7): per cell the median with its 95 % bootstrap interval (bars) and quartiles
    (thin bars), every seed's tilt faint behind (``frame``, the rows), with the
    out-of-plane threshold."""
    fig, ax = single_axes(ax, (6.0, 4.0))
    q0 = cells["g0"] * np.sin(np.radians(cells["theta0_deg"])) / 3
    if frame is not None:
        ax.scatter(frame["q0"], frame["theta_final_deg"], s=6, color="0.75", zorder=1,
                   label="each seed")
    shift = 0.012 * (q0.max() - q0.min() if len(q0) > 1 else 1.0)  # beside the medians
    ax.errorbar(q0 + shift, cells["tilt_median"],
                yerr=[cells["tilt_median"] - cells["tilt_q25"],
                      cells["tilt_q75"] - cells["tilt_median"]],
                fmt="none", ecolor="0.45", elinewidth=0.8, capsize=3, zorder=2,
                label="quartiles")
    ax.errorbar(q0, cells["tilt_median"],
                yerr=[cells["tilt_median"] - cells["tilt_median_low"],
                      cells["tilt_median_high"] - cells["tilt_median"]],
                fmt="o", ms=3.5, color="#3b0f70", elinewidth=1.6, zorder=3,
                label="median, 95% interval")
    q_out = full_linear.critical_q(16, "out-of-plane")
    ax.axvline(q_out, color="k", ls=":", lw=1.0, label=f"out-of-plane threshold, q = {q_out:.3f}")
    ax.set_xlabel(r"$q_0 = g_0 \sin\theta_0 / 3$")
    ax.set_ylabel(r"terminal tilt $\theta$ (deg)")
    ax.set_title("terminal tilt over seeds", fontsize=10)
    ax.legend(fontsize=7, framealpha=0.9, loc="best")
    return fig


def aspect_distribution(cells, frame=None, branch=None, ax=None):
    """Terminal aspect ratio against terminal q as distributions (the distributional form
    of the paper's Fig. 8): per cell the median aspect ratio with its 95 % bootstrap
    interval (bars) and quartiles (thin bars) at the median terminal q with its quartiles
    (horizontal bars), every seed faint behind (``frame``), over the steady branch
    (``branch``: a DataFrame as ``stability.branch.steady_branch`` returns, or None)."""
    fig, ax = single_axes(ax, (6.0, 4.0))
    ax.axhline(1.0, color="0.85", lw=0.8, zorder=0)
    if frame is not None:
        ax.scatter(frame["q_final"], frame["aspect_ratio"], s=6, color="0.75", zorder=1,
                   label="each seed")
    if branch is not None and len(branch):
        branch_lines(ax, branch)
    q, ratio = cells["q_final_median"], cells["aspect_median"]
    ax.errorbar(q, ratio, xerr=[q - cells["q_final_q25"], cells["q_final_q75"] - q],
                yerr=[ratio - cells["aspect_q25"], cells["aspect_q75"] - ratio],
                fmt="none", ecolor="0.45", elinewidth=0.8, capsize=2, zorder=3,
                label="quartiles")
    ax.errorbar(q, ratio, yerr=[ratio - cells["aspect_median_low"],
                                cells["aspect_median_high"] - ratio],
                fmt="o", ms=3.5, color="#3b0f70", elinewidth=1.6, zorder=4,
                label="median, 95% interval")
    ax.set_xlabel(r"terminal $q = g_0 \sin\theta / 3$")
    ax.set_ylabel("terminal aspect ratio")
    ax.set_title("terminal shape over seeds", fontsize=10)
    ax.set_xlim(left=0)
    ax.legend(fontsize=7, framealpha=0.9, loc="best")
    return fig


def distribution_summary(cells, frame, branch=None, rest_window=None):
    """The panels of a summary table (``outcome_statistics.summarize``) and its rows: the regime
    probabilities per cell (:func:`probability_phase_diagram`), the terminal tilt over the seeds
    (:func:`tilt_distribution`) and, when the table has terminal q, the aspect ratio
    over the steady branch ``branch`` (:func:`aspect_distribution`); ``rest_window``: as
    :func:`probability_phase_diagram`'s."""
    panels = 3 if "q_final_median" in cells else 2
    fig, axes = plt.subplots(1, panels, figsize=(6.6 * panels, 4.4), constrained_layout=True)
    probability_phase_diagram(cells, ax=axes[0], rest_window=rest_window)
    tilt_distribution(cells, frame, ax=axes[1])
    if panels == 3:
        aspect_distribution(cells, frame, branch=branch, ax=axes[2])
    return fig


def save_distribution_figure(table, frame, path, dpi=150, rest_window=None):
    """Draw a summary table and its rows (:func:`distribution_summary`) to ``path``: for
    the local model over its steady branch up to the largest terminal q seen, rounded up
    to a multiple of 5 (at most :data:`BRANCH_Q_MAX`), with the stable branch's window
    where ``rest_window`` is given."""
    branch = None
    q_final = frame["q_final"].to_numpy(float) if "q_final" in frame else []
    q_seen = [float(q) for q in q_final if q == q]
    if frame_model(frame).name == "local" and q_seen:
        branch = steady.steady_branch_to(
            min(BRANCH_Q_MAX, 5.0 * math.ceil(1.05 * max(q_seen) / 5.0) or 5.0))
    save(distribution_summary(table, frame, branch=branch, rest_window=rest_window), path,
         dpi=dpi)
