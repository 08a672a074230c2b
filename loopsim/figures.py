"""The paper's figures, or their corrected counterparts, from result tables.

Waszkiewicz, Szymczak & Lisicki, "Stability of sedimenting flexible loops"
(JFM 919, A14, 2021).  One function per figure; each draws into ``ax`` /
``axes`` (a new figure when None) and returns the figure.  Nothing here
integrates dynamics or changes the matplotlib backend (``loopsim figures``
chooses Agg).  Inputs are the tables loopsim writes: a sweep's
``read_results`` frame (one row per case, terminal coefficients ``x_final``)
and a run's trajectory table (one row per snapshot: ``t``, ``x``,
``multiplier``).  Computed inputs (growth rates, the steady branch) come in
as DataFrames, so every function can be drawn from stored numbers:

* Fig. 1  :func:`tension_on_shape` - the axial force N(s) = T + |x''|² along the loop;
* Fig. 3  :func:`stability_data`, :func:`stability` - growth rates against q and
  critical q against n: the paper's operator beside the full linearisation;
* Fig. 4  :func:`gallery` - terminal shapes at one θ0 across g0;
* Fig. 5  ``plots.phase_diagram(frame, paper_band=True)``;
* Fig. 6  :func:`evolution` - one trajectory: 3D, side and top views;
* Fig. 7  :func:`q_and_tilt` - q_final against q0, θ_final against θ0;
* Fig. 8  :func:`aspect_ratio` - terminal aspect ratio against q_final, with the
  steady branch (``stability.branch.steady_branch``) when given;
* Fig. 9  :func:`phase_diagrams` - phase diagrams of several sweeps side by side;
* :func:`seed_distributions` - terminal tilt and aspect ratio over seeds.

Regime colours are ``plots.REGIME_STYLE`` (the paper's: stable dark purple,
in-plane green-blue, 3D yellow); cases not resolved at their n are hollow.
"""
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.colors import Normalize, TwoSlopeNorm

from . import diagnostics, spectral, validation
from .plots import (
    PAPER_BAND, REGIME_STYLE, mark_undetermined, order_column, orders_text, phase_diagram,
)
from .stability import circle, paper

#: Colour map of time in trajectories: light yellow (start) to dark purple (end), as the paper's Fig. 6.
TIME_CMAP = "viridis_r"
#: Points per loop when drawing shapes.
CURVE_POINTS = 256


# ---------------------------------------------------------------- helpers
def _figure(axes, shape, figsize, **kwargs):
    """(figure, flat list of axes): the given ones, or a new constrained-layout grid."""
    if axes is None:
        fig, axes = plt.subplots(*shape, figsize=figsize, constrained_layout=True, **kwargs)
    axes = list(np.ravel(axes))
    return axes[0].figure, axes


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


def _regime_style(regime):
    return REGIME_STYLE.get(regime, REGIME_STYLE["failed"])


def _resolved(frame):
    if "resolved" in frame:
        return frame["resolved"].to_numpy(bool)
    return np.ones(len(frame), bool)


def _scatter_regimes(ax, frame, xcol, ycol, shift=None, size=20, label_suffix=""):
    """Scatter by regime, resolved filled and unresolved hollow, undetermined ringed red
    (``plots.mark_undetermined``); ``shift``: {regime: dx}."""
    resolved = _resolved(frame)
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


def _thresholds(n=16):
    """q thresholds: the paper's operator and the full linearisation (in-plane, out-of-plane)."""
    return dict(paper=paper.critical_q(20), in_plane=circle.critical_q(max(n, 3), "in-plane"),
                out_of_plane=circle.critical_q(max(n, 3), "out-of-plane"))


def _q_lines(ax, thresholds, vertical=True, band=True):
    line = ax.axvline if vertical else ax.axhline
    line(thresholds["paper"], color="k", lw=1.1, label=f"paper's linear stability, q = {thresholds['paper']:.2f}")
    line(thresholds["in_plane"], color="k", lw=1.0, ls="--",
         label=f"full linearisation, in-plane, q = {thresholds['in_plane']:.2f}")
    line(thresholds["out_of_plane"], color="k", lw=1.0, ls=":",
         label=f"full linearisation, out-of-plane, q = {thresholds['out_of_plane']:.2f}")
    if band:
        for i, q in enumerate(PAPER_BAND):
            line(q, color="0.55", lw=1.0, ls="-.",
                 label=f"paper's empirical in-plane band, q = {PAPER_BAND[0]:g}-{PAPER_BAND[1]:g}"
                 if i == 0 else None)


# ---------------------------------------------------------------- Fig. 3
def stability_data(n=16, q_values=None, n_values=range(3, 17), theta0_deg=90.0):
    """The numbers of Fig. 3 as two DataFrames: ``growth`` (q, paper, corrected, in_plane,
    out_of_plane: largest growth rates at truncation n) and ``critical`` (n, in_plane,
    out_of_plane, paper, corrected: critical q against n; NaN where none)."""
    q_values = np.linspace(0.0, 20.0, 81) if q_values is None else np.asarray(q_values, float)
    growth = pd.DataFrame(circle.paper_comparison(q_values, n, theta0_deg))
    critical = pd.DataFrame(circle.critical_q_table(list(n_values), theta0_deg),
                            columns=["n", "in_plane", "out_of_plane", "paper", "corrected"])
    growth.attrs["n"] = int(n)
    return growth, critical


def stability(growth, critical, axes=None):
    """Fig. 3, corrected.  Left: largest growth rate σ against q (the paper's operator, the
    full linearisation's in-plane and out-of-plane sectors); right: critical q against the
    truncation n for the same three.  Inputs from :func:`stability_data`."""
    fig, (left, right) = _figure(axes, (1, 2), (9.0, 3.6))
    n = growth.attrs.get("n")
    curves = (("paper", "k", "--", "paper's operator (§4)"),
              ("in_plane", "C3", "-", "full linearisation, in-plane"),
              ("out_of_plane", "C0", "-", "full linearisation, out-of-plane"))
    for key, colour, style, label in curves:
        left.plot(growth["q"], growth[key], color=colour, ls=style, lw=1.6, label=label)
    left.axhline(0.0, color="0.6", lw=0.8)
    left.set_ylim(-15.0, 15.0)
    left.set_xlim(growth["q"].min(), growth["q"].max())
    left.set_xlabel(r"$q = g_0 \sin\theta_0 / 3$")
    left.set_ylabel(r"largest growth rate $\sigma$")
    left.set_title("translating circle" + (f", n = {n}" if n else ""), fontsize=10)
    left.legend(fontsize=8, frameon=False, loc="upper left")
    for key, colour, style, label in curves:
        rows = critical[np.isfinite(critical[key])]
        right.plot(rows["n"], rows[key], color=colour, ls=style, marker="o", ms=3.5, lw=1.2,
                   label=f"{label}: {rows[key].iloc[-1]:.4f}" if len(rows) else label)
    right.set_xlabel("truncation order n")
    right.set_ylabel(r"critical $q$")
    right.set_title("critical q against n", fontsize=10)
    right.legend(fontsize=8, frameon=False)
    return fig


# ---------------------------------------------------------------- Fig. 4
def _side_view_basis(x):
    """Unit horizontal vectors (h, p): h along the terminal plane's horizontal line
    (viewing direction), p perpendicular to it, so that the plane is seen edge-on."""
    _, vectors = diagnostics.principal_axes(x)
    normal = vectors[:, 0]
    horizontal = np.array([normal[0], normal[1], 0.0])
    if np.linalg.norm(horizontal) < 1e-12:  # horizontal loop: any direction
        horizontal = np.array([0.0, 1.0, 0.0])
    p = horizontal / np.linalg.norm(horizontal)
    if p[1] < 0:
        p = -p
    return np.cross([0.0, 0.0, 1.0], p), p


def _plane_view(x):
    """The loop in its principal plane: (major, minor) coordinates, major axis pointing
    to the fore (lower) side on the right."""
    _, vectors = diagnostics.principal_axes(x)
    major, minor = vectors[:, 2], vectors[:, 1]
    if major[2] > 0 or (abs(major[2]) < 1e-12 and major[1] < 0):
        major = -major
    if np.cross(major, minor) @ vectors[:, 0] < 0:
        minor = -minor
    points = centred_curve(x)
    return major @ points, minor @ points


def _unit_circle(ax):
    s = np.linspace(0, 2 * np.pi, 200)
    ax.plot(np.cos(s), np.sin(s), color="0.5", lw=0.8, ls="--")


def gallery(frame, theta0_deg=30.0, max_shapes=8, axes=None):
    """Fig. 4: terminal shapes of the cases with θ0 nearest ``theta0_deg``, across g0,
    coloured by regime.  Top row: side view (gravity downwards; the terminal plane seen
    edge-on), with the unit circle and the initial tilt plane dashed.  Bottom row: the loop
    in its terminal plane, principal axes aligned (fore side right), unit circle dashed.
    Grey titles mark cases not resolved at their n."""
    if not len(frame):
        raise ValueError("no cases to draw")
    theta = frame["theta0_deg"].to_numpy(float)
    chosen = np.unique(theta)[np.argmin(np.abs(np.unique(theta) - theta0_deg))]
    rows = frame[np.isclose(theta, chosen)].sort_values("g0")
    if len(rows) > max_shapes:
        rows = rows.iloc[np.unique(np.round(np.linspace(0, len(rows) - 1, max_shapes)).astype(int))]
    count = len(rows)
    fig, flat = _figure(axes, (2, count), (1.25 * count + 0.4, 3.0), squeeze=False)
    top, bottom = flat[:count], flat[count:]
    resolved = _resolved(rows)
    t0 = np.radians(chosen)
    for i, (_, row) in enumerate(rows.iterrows()):
        x = coefficients(row["x_final"], row[order_column(rows)])
        colour = _regime_style(row["regime"])["color"]
        h, p = _side_view_basis(x)
        points = centred_curve(x)
        ax = top[i]
        _unit_circle(ax)
        ax.plot([-np.cos(t0) * 1.3, np.cos(t0) * 1.3], [-np.sin(t0) * 1.3, np.sin(t0) * 1.3],
                color="0.5", lw=0.8, ls="--")
        ax.plot(p @ points, points[2], color=colour, lw=1.8)
        ax.annotate("", xy=(1.25, -1.05), xytext=(1.25, -0.35),
                    arrowprops=dict(arrowstyle="-|>", color="k", lw=0.8))
        ax.set_title(f"$g_0$ = {row['g0']:.0f}\nq0 = {row['q0']:.1f}, θ = {row['theta_final_deg']:.0f}°",
                     fontsize=7, color="k" if resolved[i] else "0.45")
        ax = bottom[i]
        _unit_circle(ax)
        major, minor = _plane_view(x)
        ax.plot(major, minor, color=colour, lw=1.8)
        ax.set_title(f"AR = {row['aspect_ratio']:.2f}" + ("" if resolved[i] else "\n(not resolved)"),
                     fontsize=7, color="k" if resolved[i] else "0.45")
    for ax in top + bottom:
        ax.set_aspect("equal")
        ax.set_xlim(-1.9, 1.9)
        ax.set_ylim(-1.9, 1.9)
        ax.set_xticks([])
        ax.set_yticks([])
        for spine in ax.spines.values():
            spine.set_linewidth(0.4)
    top[0].set_ylabel("side view", fontsize=8)
    bottom[0].set_ylabel("in its plane", fontsize=8)
    fig.suptitle(f"terminal shapes, θ0 = {chosen:g}°, {orders_text(rows)} (colour: regime)",
                 fontsize=9)
    return fig


# ---------------------------------------------------------------- Fig. 6
def _time_colours(times):
    norm = Normalize(vmin=float(np.min(times)), vmax=float(np.max(times)) or 1.0)
    return plt.get_cmap(TIME_CMAP), norm


def settling_index(trajectory, tilt_tol=0.01, aspect_tol=1e-4):
    """Index of the first snapshot after which the tilt and the aspect ratio change by no
    more than ``tilt_tol`` degrees and ``aspect_tol`` between snapshots (the last index
    if they never settle)."""
    tilt = trajectory["theta_deg"].to_numpy(float)
    ratio = trajectory["aspect_ratio"].to_numpy(float)
    moving = (np.abs(np.diff(tilt)) > tilt_tol) | (np.abs(np.diff(ratio)) > aspect_tol)
    moved = np.nonzero(moving)[0]
    return int(moved[-1] + 1) if len(moved) else 0


def evolution(trajectory, snapshots=9, title="", fig=None, t_max="settled"):
    """Fig. 6: shape evolution of one run (trajectory table), centred on the centre of
    mass at each time: 3D view, side view (along x: y-z, the initial tilt plane edge-on)
    and top view (x-y), ``snapshots`` snapshots at regular times from t = 0 to ``t_max``,
    coloured by time (light yellow first, dark purple last).  ``t_max``: a time, None (the
    whole run) or "settled" (until the shape stops changing, :func:`settling_index`).
    ``fig``: a figure to draw into (3 axes are added)."""
    if not len(trajectory):
        raise ValueError("the trajectory has no snapshots")
    if fig is None:
        fig = plt.figure(figsize=(10.0, 3.4), constrained_layout=True)
    ax3d = fig.add_subplot(1, 3, 1, projection="3d")
    side = fig.add_subplot(1, 3, 2)
    top = fig.add_subplot(1, 3, 3)
    times = trajectory["t"].to_numpy(float)
    if t_max == "settled":
        last = settling_index(trajectory) if {"theta_deg", "aspect_ratio"} <= set(trajectory) \
            else len(trajectory) - 1
        last = max(last, 1) if len(trajectory) > 1 else 0
    else:
        last = len(trajectory) - 1 if t_max is None else int(np.searchsorted(times, t_max, "right") - 1)
    index = np.unique(np.round(np.linspace(0, max(last, 0), snapshots)).astype(int))
    times = times[: index[-1] + 1]
    cmap, norm = _time_colours(times)
    for i in index:
        points = centred_curve(coefficients(trajectory["x"].iloc[i]))
        colour = cmap(norm(times[i]))
        ax3d.plot(points[0], points[1], points[2], color=colour, lw=1.2)
        side.plot(points[1], points[2], color=colour, lw=1.2)
        top.plot(points[0], points[1], color=colour, lw=1.2)
    ax3d.set(xlabel="x", ylabel="y", zlabel="z")
    ax3d.set_box_aspect((1, 1, 1))
    lim = (-1.6, 1.6)
    ax3d.set(xlim=lim, ylim=lim, zlim=lim)
    ax3d.tick_params(labelsize=6)
    side.set(xlabel="y (centred)", ylabel="z (centred)", title="side view (along x)",
             aspect="equal", xlim=lim, ylim=lim)
    top.set(xlabel="x (centred)", ylabel="y (centred)", title="top view", aspect="equal",
            xlim=lim, ylim=lim)
    for ax in (side, top):
        ax.title.set_fontsize(9)
    side.annotate("", xy=(1.45, -1.45), xytext=(1.45, -0.75),
                  arrowprops=dict(arrowstyle="-|>", color="k", lw=0.8))
    mappable = plt.cm.ScalarMappable(norm=norm, cmap=cmap)
    fig.colorbar(mappable, ax=[side, top], label="time t", shrink=0.85)
    ax3d.set_title(title, fontsize=9)
    return fig


# ---------------------------------------------------------------- Fig. 1 colouring
def tension_on_shape(x, multiplier, ax=None, title="", norm=None):
    """The paper's Fig. 1 colouring: the loop (3D, centred) coloured by the axial force
    N(s) = T(s) + |x''(s)|² (positive: stretched, aft; negative: compressed, fore), with
    a colour bar centred at N = 0 and the arc-length origin s = 0 marked."""
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    if ax is None:
        fig = plt.figure(figsize=(4.6, 3.8), constrained_layout=True)
        ax = fig.add_subplot(projection="3d")
    x = np.asarray(x, dtype=float)
    s, force = diagnostics.tension_profile(x, np.asarray(multiplier, dtype=float))
    s = np.append(s, 2 * np.pi)
    force = np.append(force, force[0])
    xc = x.copy()
    xc[:, 0] = 0.0
    points = spectral.evaluate(xc, s).T
    segments = np.stack([points[:-1], points[1:]], axis=1)
    if norm is None:
        bound = max(float(np.max(np.abs(force))), 1e-12)
        norm = TwoSlopeNorm(vcenter=0.0, vmin=-bound, vmax=bound)
    lines = Line3DCollection(segments, cmap="RdBu_r", norm=norm, linewidths=3.0)
    lines.set_array(0.5 * (force[:-1] + force[1:]))
    ax.add_collection(lines)
    ax.scatter(*points[0], color="k", s=12)
    ax.text(*points[0], "  s = 0", fontsize=7)
    lim = (-1.4, 1.4)
    ax.set(xlim=lim, ylim=lim, zlim=lim, xlabel="x", ylabel="y", zlabel="z")
    ax.set_box_aspect((1, 1, 1))
    ax.tick_params(labelsize=6)
    ax.set_title(title, fontsize=9)
    ax.figure.colorbar(lines, ax=ax, shrink=0.7, pad=0.1, label=r"axial force $N = T + |x''|^2$")
    return ax.figure


def tension_figure(trajectory, rows=(0, -1), title=""):
    """Fig. 1 colouring for the first and last snapshot of a run side by side."""
    fig = plt.figure(figsize=(4.2 * len(rows), 3.7), constrained_layout=True)
    for k, i in enumerate(rows):
        row = trajectory.iloc[i]
        ax = fig.add_subplot(1, len(rows), k + 1, projection="3d")
        x = coefficients(row["x"])
        tension_on_shape(x, np.asarray(row["multiplier"], float), ax=ax,
                         title=f"{title}t = {row['t']:.3g}")
    return fig


# ---------------------------------------------------------------- Fig. 5, 9
def phase_diagrams(frames, axes=None):
    """Fig. 9: phase diagrams (``plots.phase_diagram`` with the paper's band) of several
    sweeps side by side, one per frame (for example n = 4 and n = 8)."""
    frames = list(frames)
    if not frames:
        raise ValueError("no sweeps to draw")
    fig, flat = _figure(axes, (1, len(frames)), (5.2 * len(frames) + 1.8, 4.0), squeeze=False)
    for i, (frame, ax) in enumerate(zip(frames, flat)):
        phase_diagram(frame, ax=ax, paper_band=True)
        if i < len(frames) - 1:
            ax.get_legend().remove()
    return fig


# ---------------------------------------------------------------- Fig. 7
def q_and_tilt(frame, thresholds=None, axes=None, reference=None):
    """Fig. 7.  Left: terminal q (= g0 sin θ_final / 3) against q0, with the thresholds
    (the paper's 14.56 and its empirical band 10.5-18.5; the full linearisation's 8.90
    and 10.65).  Right: θ_final against θ0 (stable shifted 1° left, in-plane 1° right, as
    in the paper).  ``reference``: an optional second table (for example resolved runs at
    higher n), drawn with black-edged diamonds."""
    fig, (left, right) = _figure(axes, (1, 2), (10.0, 4.6))
    thresholds = thresholds or _thresholds(int(frame[order_column(frame)].max()) if len(frame) else 16)
    q_max = float(max(frame["q0"].max(), frame["q_final"].max())) * 1.05 if len(frame) else 1.0
    left.plot([0, q_max], [0, q_max], color="0.8", lw=0.8, zorder=1)
    right.plot([0, 92], [0, 92], color="0.8", lw=0.8, zorder=1)
    _q_lines(left, thresholds, vertical=False)
    _scatter_regimes(left, frame, "q0", "q_final")
    _scatter_regimes(right, frame, "theta0_deg", "theta_final_deg",
                     shift={"stable": -1.0, "in-plane": 1.0})
    for ax, xcol, ycol in ((left, "q0", "q_final"), (right, "theta0_deg", "theta_final_deg")):
        if reference is not None and len(reference):
            ax.scatter(reference[xcol], reference[ycol], marker="D", s=26, facecolors="none",
                       edgecolors="k", linewidths=0.9, zorder=4,
                       label=f"{orders_text(reference)} (reference)")
    left.set(xlabel=r"initial $q_0 = g_0 \sin\theta_0 / 3$", ylabel=r"terminal $q = g_0 \sin\theta / 3$",
             xlim=(0, q_max), ylim=(0, q_max))
    right.set(xlabel=r"initial tilt $\theta_0$ (deg)", ylabel=r"terminal tilt $\theta$ (deg)",
              xlim=(0, 92), ylim=(0, 92))
    handles, labels = left.get_legend_handles_labels()
    fig.legend(handles, labels, fontsize=7, frameon=False, loc="outside lower center", ncol=3)
    fig.suptitle(f"initial against terminal state, {orders_text(frame)}", fontsize=10)
    return fig


# ---------------------------------------------------------------- Fig. 8
def aspect_ratio(frame, branch=None, ax=None, reference=None, q_max=None):
    """Fig. 8: terminal aspect ratio (largest / middle covariance eigenvalue) against the
    terminal q, by regime.  ``branch``: a DataFrame with columns q, aspect_ratio,
    stable_in_plane, stable_out_of_plane (``stability.branch.steady_branch``): drawn solid
    where stable in and out of plane, dashed elsewhere.  ``reference``: an optional
    second table drawn with black-edged diamonds.  ``q_max``: right end of the q axis
    (the number of cases beyond it is written on the plot)."""
    fig, ax = _single(ax, (6.6, 4.2))
    ax.axhline(1.0, color="0.8", lw=0.8, zorder=1)
    _scatter_regimes(ax, frame, "q_final", "aspect_ratio")
    if reference is not None and len(reference):
        ax.scatter(reference["q_final"], reference["aspect_ratio"], marker="D", s=26,
                   facecolors="none", edgecolors="k", linewidths=0.9, zorder=4,
                   label=f"{orders_text(reference)} (reference)")
    if branch is not None and len(branch):
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
    ax.set_xlabel(r"terminal $q = g_0 \sin\theta / 3$")
    ax.set_ylabel("terminal aspect ratio (variances)")
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
                    transform=ax.transAxes, ha="right", va="bottom", fontsize=7, color="0.3")
        visible = frame[frame["q_final"] <= q_max]["aspect_ratio"]
        if len(visible):
            ax.set_ylim(0.9, max(1.1, float(visible.max()) * 1.08))
    ax.legend(fontsize=7, frameon=False, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    return fig


def _single(ax, figsize):
    """(figure, axes): ``ax`` and its figure, or a new figure with one axes."""
    if ax is None:
        fig, ax = plt.subplots(figsize=figsize, constrained_layout=True)
        return fig, ax
    return ax.figure, ax


# ---------------------------------------------------------------- seeds
def seed_distributions(frames, labels=None, axes=None, bins=12):
    """Terminal tilt and aspect ratio over seeds: one histogram per table (for example
    the same (g0, θ0) at n = 6 and n = 16), the initial tilt marked."""
    frames = list(frames)
    if not frames:
        raise ValueError("no tables to draw")
    labels = labels or [orders_text(f) for f in frames]
    fig, (left, right) = _figure(axes, (1, 2), (9.0, 3.4))
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
        left.axvline(value, color="0.3", ls="--", lw=1.0, label=f"θ0 = {value:g}°")
    left.set(xlabel=r"terminal tilt $\theta$ (deg)", ylabel="seeds")
    right.set(xlabel="terminal aspect ratio (variances)", ylabel="seeds")
    left.legend(fontsize=7, frameon=False)
    right.legend(fontsize=7, frameon=False)
    fig.suptitle("terminal outcomes over seeds, g0 = " + ", ".join(f"{v:g}" for v in g0), fontsize=10)
    return fig


# ---------------------------------------------------------------- from files: ``loopsim figures``
#: Figure names of :func:`write_figures` (``--only``), in drawing order.
FIGURE_NAMES = ("stability", "gallery", "phase", "q_tilt", "aspect", "phase_n", "seeds",
                "evolution", "tension")


def read_run(path):
    """(trajectory DataFrame, summary dict) of a ``loopsim run --out`` file."""
    import pyarrow.parquet as pq

    from . import io

    try:
        meta = io.read_metadata(path)
        if "summary" not in meta:
            raise ValueError(f"{path!r} is not a run file (written by 'loopsim run --out'): "
                             "no run summary in its metadata")
        frame = pq.read_table(path).to_pandas()
    except (OSError, ValueError) as exc:
        raise ValueError(f"cannot read {path!r}: {str(exc).splitlines()[0]}") from None
    missing = {"t", "x", "multiplier"} - set(frame.columns)
    if missing:
        raise ValueError(f"{path!r} is not a trajectory table (missing {sorted(missing)})")
    return frame, meta["summary"]


def _read_sweep(path):
    from . import io

    try:
        frame = io.read_results(path)
    except (OSError, ValueError) as exc:
        raise ValueError(f"cannot read sweep {path!r}: {str(exc).splitlines()[0]}") from None
    if not len(frame):
        raise ValueError(f"sweep {path!r} holds no finished cases")
    return frame


def _kind(frame):
    """'seeds' (some point has >= 3 seeds), 'grid' (a full g0 x θ0 product, >= 3 of each)
    or 'reference' (anything else: a list of cases)."""
    if frame.groupby(["g0", "theta0_deg", "n"]).size().max() >= 3:
        return "seeds"
    g0, theta0 = frame["g0"].nunique(), frame["theta0_deg"].nunique()
    points = len(frame[["g0", "theta0_deg"]].drop_duplicates())
    if g0 >= 3 and theta0 >= 3 and points == g0 * theta0:
        return "grid"
    return "reference"


def _label(frame):
    method = ("/".join(sorted(map(str, frame["method"].dropna().unique()))) if "method" in frame
              else (frame.attrs.get("loopsim", {}).get("sweep_config", {}) or {}).get("method"))
    return orders_text(frame) + (f", {method}" if method else "")


def load_branch(n=12, q_max=25.0):
    """The steady branch from ``stability.branch.steady_branch`` (a DataFrame), or None
    with the reason when that module or function is not there."""
    try:
        from .stability import branch as steady
    except ImportError as exc:
        return None, f"no steady branch: {exc}"
    function = getattr(steady, "steady_branch", None)
    if function is None:
        return None, "no steady branch: loopsim.stability.branch has no steady_branch()"
    frame = function(n=n, q_max=q_max)
    frame.attrs.setdefault("n", n)
    return frame, None


def write_figures(sweep_dir, others=(), out=".", only=None, gallery_theta0=30.0,
                  stability_n=16, branch_n=12, branch=True, dpi=110, log=print):
    """Draw every figure the inputs allow into ``out`` and return {name: path}.

    ``sweep_dir``: the main sweep (Figs. 4, 5, 7, 8).  ``others``: more sweep directories
    (a grid at another n: Fig. 9; several seeds of one point: the seed distributions;
    any other: a reference drawn over Figs. 7 and 8, and its own gallery) and run files
    (``loopsim run --out``: Fig. 6 and the tension colouring).  Fig. 3 needs no input.
    ``only``: a subset of :data:`FIGURE_NAMES`.  Bad input raises ValueError, before
    ``out`` (made if absent) is created or anything drawn.
    """
    import os

    only = set(FIGURE_NAMES if only is None else only)
    unknown = only - set(FIGURE_NAMES)
    if unknown:
        raise ValueError(f"unknown figure(s) {sorted(unknown)}; choose from {', '.join(FIGURE_NAMES)}")
    validation.check_count("dpi", dpi, 20, validation.MAX_DPI, "print quality; the pixel "
                           "count grows with its square")
    validation.check_tilt("gallery_theta0", gallery_theta0)
    validation.check_count("branch_n", branch_n, 4, validation.MAX_BRANCH_N,
                           "the continuation's cost grows like n^3 per point")
    validation.check_output_directory("out", out)
    if not os.path.isdir(sweep_dir):
        raise ValueError(f"no sweep directory at {sweep_dir!r}")
    main = _read_sweep(sweep_dir)
    sweeps, runs = {"grid": [], "seeds": [], "reference": []}, []
    for path in others:
        if os.path.isdir(path):
            frame = _read_sweep(path)
            sweeps[_kind(frame)].append((path, frame))
        elif os.path.isfile(path):
            runs.append((path, *read_run(path)))
        else:
            raise ValueError(f"no such file or directory: {path!r}")
    os.makedirs(out, exist_ok=True)
    written = {}

    def save(name, fig):
        path = os.path.join(out, f"{name}.png")
        fig.savefig(path, dpi=dpi)
        plt.close(fig)
        written[name] = path
        log(f"{name}: {path}")

    reference = (pd.concat([f for _, f in sweeps["reference"]], ignore_index=True)
                 if sweeps["reference"] else None)
    if "stability" in only:
        save("fig3_stability", stability(*stability_data(n=stability_n)))
    if "gallery" in only:
        save("fig4_gallery", gallery(main, gallery_theta0))
        for path, frame in sweeps["reference"]:
            if (np.abs(frame["theta0_deg"] - gallery_theta0) < 1e-9).sum() >= 3:
                save(f"fig4_gallery_{os.path.basename(os.path.normpath(path))}",
                     gallery(frame, gallery_theta0))
    if "phase" in only:
        save("fig5_phase", phase_diagram(main, paper_band=True))
    if "q_tilt" in only:
        save("fig7_q_tilt", q_and_tilt(main, reference=reference))
    if "aspect" in only:
        steady, note = (None, "steady branch not requested") if not branch else load_branch(branch_n)
        if note:
            log(note)
        save("fig8_aspect", aspect_ratio(main, steady, reference=reference, q_max=40.0))
    if "phase_n" in only and sweeps["grid"]:
        frames = sorted([f for _, f in sweeps["grid"]], key=lambda f: int(f["n"].min()))
        save("fig9_phase_n", phase_diagrams(frames))
    if "seeds" in only and sweeps["seeds"]:
        frames = [f for _, f in sweeps["seeds"]]
        save("seed_distributions", seed_distributions(frames, [_label(f) for f in frames]))
    for path, trajectory, summary in runs:
        stem = os.path.splitext(os.path.basename(path))[0]
        used = summary.get("n_used", summary["n"])
        order = f"n = {summary['n']}" if used == summary["n"] else f"n auto (n_used = {used})"
        title = f"g0 = {summary['g0']:g}, θ0 = {summary['theta0_deg']:.3g}°, {order}"
        if "evolution" in only:
            save(f"fig6_evolution_{stem}", evolution(trajectory, title=title))
        if "tension" in only:
            save(f"fig1_tension_{stem}", tension_figure(trajectory, title=title + "\n"))
    return written
