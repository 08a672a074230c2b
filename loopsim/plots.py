"""Publication-style figures from result tables (reads data, never integrates dynamics).

Each function draws into ``ax`` (a new figure when None) and returns the
figure; none changes the matplotlib backend (the CLI chooses Agg).
"""
import os

import matplotlib.pyplot as plt
import numpy as np

from . import models, spectral
from .stability import circle, paper

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


def _axes(ax, figsize):
    if ax is None:
        fig, ax = plt.subplots(figsize=figsize, constrained_layout=True)
        return fig, ax
    return ax.figure, ax


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


def phase_diagram(frame, ax=None, paper_band=False):
    """g0 against θ0 coloured by regime (hollow: the case is not resolved at its n, see
    ``outcomes.Thresholds.resolved``; ringed red: not determined), with the curves g0 = 3 q_c / sin θ0 of the
    paper's linear stability (q_c = 14.561, wrong sign) and of the full linearisation of
    the circle at the sweep's largest truncation (``n_used`` for ``--n auto`` rows;
    in-plane q_c ≈ 8.90, out-of-plane ≈ 10.65), in the rows' model (nonlocal: its
    thresholds at θ0 = 90°, drawn as g0 = 3 q_c / sin θ0).
    ``paper_band``: also the paper's empirical in-plane band q = 10.5 and 18.5 (its Fig. 5)."""
    fig, ax = _axes(ax, (6.6, 4.0))
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
        q_sector = circle.critical_q(max(order, 3), sector, model=model)
        ax.plot(theta, 3 * q_sector / np.sin(np.radians(theta)), "k", ls=style, lw=1.2,
                label=f"full linearisation,\n{sector}, q = {q_sector:.3f}")
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


def growth_rates(n=16, q_values=None, theta0_deg=90.0, w=None, ax=None, model=None):
    """Largest growth rates vs q: the paper's operator, the corrected operator and both
    sectors of the full Jacobian (of ``model``, a ``models.Model``; default local), with
    the critical q of each marked."""
    kwargs = dict({} if w is None else dict(w=w), **({} if model is None else dict(model=model)))
    fig, ax = _axes(ax, (6.4, 4.2))
    q_values = np.linspace(0.0, 20.0, 81) if q_values is None else np.asarray(q_values, float)
    rows = circle.paper_comparison(q_values, n, theta0_deg, **kwargs)
    get = lambda key: [r[key] for r in rows]  # noqa: E731
    ax.plot(q_values, get("paper"), "k--", label="paper's operator (§4)")
    ax.plot(q_values, get("out_of_plane"), "C0-", lw=2, label="full J, out-of-plane")
    ax.plot(q_values, get("corrected"), "C1:", lw=1.5, label="corrected operator")
    ax.plot(q_values, get("in_plane"), "C3-", lw=2, label="full J, in-plane")
    ax.axhline(0.0, color="0.6", lw=0.8)
    for sector, color in (("in-plane", "C3"), ("out-of-plane", "C0")):
        qc = circle.critical_q(n, sector, theta0_deg, **kwargs)
        ax.axvline(qc, color=color, lw=0.8, ls="--")
        ax.annotate(f"{qc:.4f}", (qc, -14), color=color, rotation=90, ha="right", va="bottom")
    qp = paper.critical_q(n)
    ax.annotate(f"{qp:.4f}", (qp, -14), color="k", rotation=90, ha="right", va="bottom")
    ax.set_ylim(-15, 15)
    ax.set_xlabel("q = g0 sin θ0 / 3")
    ax.set_ylabel("largest growth rate σ")
    ax.set_title(f"translating circle, n = {n}{model_text(model or models.LOCAL)}")
    ax.legend(frameon=False)
    return fig


def nonlocal_thresholds(eps_values=(1e-2, 3e-3, 1e-3, 1e-4, 1e-6, 1e-9, 1e-12), n=8, ax=None):
    """Critical q of the translating circle (θ0 = 90°, in-plane and out-of-plane) under
    nonlocal SBT against the slenderness ε, with the local model's thresholds (ε → 0)."""
    fig, ax = _axes(ax, (6.4, 4.2))
    eps = np.sort(np.asarray(eps_values, dtype=float))
    for sector, color in (("in-plane", "C3"), ("out-of-plane", "C0")):
        local = circle.critical_q(n, sector)
        q = [circle.critical_q(n, sector, model=models.choose("nonlocal", e)) for e in eps]
        ax.semilogx(eps, q, "o-", color=color, label=f"nonlocal SBT, {sector}")
        ax.axhline(local, color=color, ls="--", lw=1.0, label=f"local SBT, {sector}: {local:.4f}")
    ax.invert_xaxis()
    ax.set_xlabel("slenderness ε = a / L")
    ax.set_ylabel("critical q = g0 sin θ0 / 3")
    ax.set_title(f"translating circle at θ0 = 90°, n = {n}", fontsize=10)
    ax.legend(frameon=False, fontsize=8)
    return fig


def model_outcomes(frames):
    """One column per results table (one model each, ``frame_model``): terminal tilt
    θ_final against θ0 (top) and terminal aspect ratio against q0 = g0 sin θ0 / 3 (bottom),
    coloured by regime, with the model's thresholds of the translating circle at the
    table's largest truncation (θ0 = 90° values for the nonlocal model) as vertical lines."""
    fig, axes = plt.subplots(2, len(frames), figsize=(1.0 + 3.3 * len(frames), 6.2),
                             sharex="row", sharey="row", constrained_layout=True,
                             squeeze=False)
    for column, frame in enumerate(frames):
        model = frame_model(frame)
        tilt, aspect = axes[0, column], axes[1, column]
        for regime, style in REGIME_STYLE.items():
            rows = frame[frame["regime"] == regime]
            if regime == "failed" or not len(rows):
                continue  # a failed row has no terminal state
            for ax, x, y in ((tilt, "theta0_deg", "theta_final_deg"),
                             (aspect, "q0", "aspect_ratio")):
                ax.scatter(rows[x], rows[y], s=20, facecolors="none", lw=1.1,
                           edgecolors=style["color"], marker=style["marker"],
                           label=style["label"])
        tilt.plot([0, 90], [0, 90], color="0.8", lw=0.8, zorder=1)
        order = max(int(frame[order_column(frame)].max()), 3)
        for sector, style in (("in-plane", "--"), ("out-of-plane", ":")):
            aspect.axvline(circle.critical_q(order, sector, model=model), color="k", ls=style,
                           lw=1.0, label=f"circle, {sector}")
        failed = int((frame["regime"] == "failed").sum())
        name = "local SBT" if model.name == "local" else f"nonlocal SBT, ε = {model.slenderness:g}"
        tilt.set_title(f"{name}\n{orders_text(frame)}" + (f", {failed} failed" if failed else ""),
                       fontsize=9)
        tilt.set_xlabel(r"initial tilt $\theta_0$ (deg)")
        aspect.set_xlabel(r"$q_0 = g_0 \sin\theta_0 / 3$")
    axes[0, 0].set_ylabel(r"terminal tilt $\theta_{final}$ (deg)")
    axes[1, 0].set_ylabel("terminal aspect ratio")
    axes[1, -1].legend(fontsize=7, frameon=False, loc="upper left")
    return fig


def save(fig, path, dpi=200):
    """Write ``fig`` to ``path`` (its directory made if absent; atomically: a failed write
    leaves no file) and close it."""
    from . import io

    try:
        io.write_file_atomically(path, lambda tmp: fig.savefig(
            tmp, dpi=dpi, format=os.path.splitext(path)[1][1:] or None))
    finally:
        plt.close(fig)
    return path


def trajectory(frame, n, title="", axes=None):
    """Snapshots of one run (a trajectory table: columns t, x, theta_deg, aspect_ratio):
    left, the loop seen face-on (each snapshot, centred on its centre of mass, projected
    on the plane of the last snapshot's two largest principal axes) and coloured by time,
    with a colour bar; right, tilt and aspect ratio against time.  ``axes``: a pair, or
    None."""
    from matplotlib.colors import Normalize

    from . import diagnostics

    if axes is None:
        fig, axes = plt.subplots(1, 2, figsize=(9.6, 3.9), constrained_layout=True)
    ax_shape, ax_time = axes
    s = np.linspace(0.0, 2.0 * np.pi, 200)
    times = frame["t"].to_numpy(float)
    cmap = plt.get_cmap("viridis_r")  # light yellow first, dark purple last (as the paper)
    norm = Normalize(vmin=times.min(), vmax=times.max() if times.max() > times.min() else times.min() + 1)
    shapes = [np.array(c, dtype=float).reshape(3, 2 * n + 1) for c in frame["x"]]
    _, vectors = diagnostics.principal_axes(shapes[-1])
    major, minor = vectors[:, 2], vectors[:, 1]
    for t, x in zip(times, shapes):
        x[:, 0] = 0.0  # centred: the mean coefficient is the centre of mass
        points = spectral.evaluate(x, s)
        ax_shape.plot(major @ points, minor @ points, color=cmap(norm(t)), lw=1)
    ax_shape.set(xlabel="along the major axis", ylabel="along the minor axis",
                 aspect="equal", title=(title + "\n" if title else "")
                 + "face-on (the last shape's principal plane)")
    ax_shape.title.set_fontsize(10)
    ax_shape.figure.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax_shape,
                             label="time t", shrink=0.9)
    ax_time.plot(frame["t"], frame["theta_deg"], color="C0")
    ax_ratio = ax_time.twinx()
    ax_ratio.plot(frame["t"], frame["aspect_ratio"], color="C1")
    ax_time.set_xlabel("time t")
    ax_time.set_ylabel("tilt θ (deg)", color="C0")
    ax_ratio.set_ylabel("aspect ratio (variance along the\nmajor / minor principal axis)",
                        color="C1")
    ax_time.set_title("tilt (blue) and aspect ratio (orange) against time", fontsize=10)
    return ax_shape.figure


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


def probability_phase_diagram(cells, frame=None, ax=None, style="pie"):
    """The phase diagram read as probabilities: each cell of a summary table
    (``loopsim.summarize``) at (θ0, g0) as a pie of its regime probabilities
    (``style="pie"``, :func:`regime_pies`) or coloured by its probability of ending 3D
    (``style="colour"``, labelled with P(in-plane) when it is neither 0 nor 1); ringed
    red where any seed is not determined; with the full linearisation's thresholds
    (``q_c`` at n = 16)."""
    if style not in ("pie", "colour"):
        raise ValueError(f"style must be 'pie' or 'colour', got {style!r}")
    check_one_cell_per_point(cells)
    fig, ax = _axes(ax, (6.8, 4.0))
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
    mixed = cells[cells["determined"] < cells["seeds"]]
    if len(mixed):
        ax.scatter(mixed["theta0_deg"], mixed["g0"], s=230 if style == "pie" else 150,
                   facecolors="none", edgecolors="#d62728", linewidths=0.9, zorder=4,
                   label="some seeds not determined")
    theta = np.linspace(1.0, 90.0, 300)
    for sector, line in (("in-plane", "--"), ("out-of-plane", ":")):
        q_sector = circle.critical_q(16, sector)
        ax.plot(theta, 3 * q_sector / np.sin(np.radians(theta)), "k", ls=line, lw=1.0,
                label=f"{sector} threshold, q = {q_sector:.3f}")
    ax.set_xlim(0, 92)
    ax.set_ylim(0, 1.08 * cells["g0"].max())
    ax.set_xlabel(r"initial tilt $\theta_0$ (deg)")
    ax.set_ylabel(r"$g_0$ (gravity / stiffness)")
    seeds = sorted(set(int(k) for k in cells["seeds"]))
    count = str(seeds[0]) if len(seeds) == 1 else f"{seeds[0]}-{seeds[-1]}"
    ax.set_title(f"regime probabilities per cell over {count} seeds" if style == "pie" else
                 f"P(3D) per cell over {count} seeds (numbers: P(in-plane))", fontsize=10)
    ax.legend(fontsize=7, frameon=False, loc="upper center", bbox_to_anchor=(0.5, -0.14),
              ncol=3)
    return fig


def tilt_distribution(cells, frame=None, ax=None):
    """Terminal tilt against q0 as distributions (the distributional form of the paper's
    Fig. 7): per cell the median with its 95 % bootstrap interval (bars) and quartiles
    (thin bars), every seed's tilt faint behind (``frame``, the rows), with the
    out-of-plane threshold."""
    fig, ax = _axes(ax, (6.0, 4.0))
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
    q_out = circle.critical_q(16, "out-of-plane")
    ax.axvline(q_out, color="k", ls=":", lw=1.0, label=f"out-of-plane threshold, q = {q_out:.3f}")
    ax.set_xlabel(r"$q_0 = g_0 \sin\theta_0 / 3$")
    ax.set_ylabel(r"terminal tilt $\theta$ (deg)")
    ax.set_title("terminal tilt over seeds", fontsize=10)
    ax.legend(fontsize=7, framealpha=0.9, loc="best")
    return fig


def branch_lines(ax, branch):
    """The steady branch: solid where stable in and out of plane, dashed elsewhere."""
    stable = (branch["stable_in_plane"].to_numpy(bool)
              & branch["stable_out_of_plane"].to_numpy(bool))
    q, ar = branch["q"].to_numpy(float), branch["aspect_ratio"].to_numpy(float)
    order = branch.attrs.get("n")
    for flag, style, label in ((True, "-", "steady shapes, stable"),
                               (False, "--", "steady shapes, unstable")):
        y = np.where(stable == flag, ar, np.nan)
        # keep the segments joined where stability changes
        joined = y.copy()
        change = np.nonzero(stable[1:] != stable[:-1])[0]
        joined[change + (0 if flag else 1)] = ar[change + (0 if flag else 1)]
        joined[change + (1 if flag else 0)] = ar[change + (1 if flag else 0)]
        if np.any(np.isfinite(joined)):
            ax.plot(q, joined, color="k", ls=style, lw=1.3,
                    label=label + (f" (n = {order})" if order else ""), zorder=2)


def aspect_distribution(cells, frame=None, branch=None, ax=None):
    """Terminal aspect ratio against terminal q as distributions (the distributional form
    of the paper's Fig. 8): per cell the median aspect ratio with its 95 % bootstrap
    interval (bars) and quartiles (thin bars) at the median terminal q with its quartiles
    (horizontal bars), every seed faint behind (``frame``), over the steady branch
    (``branch``: a DataFrame as ``stability.branch.steady_branch`` returns, or None)."""
    fig, ax = _axes(ax, (6.0, 4.0))
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


def distribution_summary(cells, frame, branch=None):
    """The panels of a summary table (``summary.summarize``) and its rows: the regime
    probabilities per cell (:func:`probability_phase_diagram`), the terminal tilt over the seeds
    (:func:`tilt_distribution`) and, when the table has terminal q, the aspect ratio
    over the steady branch ``branch`` (:func:`aspect_distribution`)."""
    panels = 3 if "q_final_median" in cells else 2
    fig, axes = plt.subplots(1, panels, figsize=(6.6 * panels, 4.4), constrained_layout=True)
    probability_phase_diagram(cells, ax=axes[0])
    tilt_distribution(cells, frame, ax=axes[1])
    if panels == 3:
        aspect_distribution(cells, frame, branch=branch, ax=axes[2])
    return fig
