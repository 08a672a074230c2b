"""Fig. 6 (shape evolution of runs, coloured by time) and the Fig. 1 colouring (axial force)."""
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import Normalize, TwoSlopeNorm

from .. import diagnostics, spectral
from .style import TIME_CMAP, centred_curve, coefficients

#: Half-width of the views of Fig. 6 (the released loop has unit radius).
VIEW_LIMIT = 1.6


def time_colours(t_range):
    """(colour map, norm) of time over ``t_range`` = (first, last)."""
    first, last = float(t_range[0]), float(t_range[1])
    top = last if last > first else first + 1.0
    return plt.get_cmap(TIME_CMAP), Normalize(vmin=first, vmax=top)


def settling_index(trajectory, tilt_tol=0.01, aspect_tol=1e-4):
    """Index of the first snapshot after which the tilt and the aspect ratio change by no
    more than ``tilt_tol`` degrees and ``aspect_tol`` between snapshots (the last index
    if they never settle)."""
    tilt = trajectory["theta_deg"].to_numpy(float)
    ratio = trajectory["aspect_ratio"].to_numpy(float)
    moving = (np.abs(np.diff(tilt)) > tilt_tol) | (np.abs(np.diff(ratio)) > aspect_tol)
    moved = np.nonzero(moving)[0]
    return int(moved[-1] + 1) if len(moved) else 0


def snapshot_indices(trajectory, snapshots=9, t_max="settled"):
    """Indices of ``snapshots`` snapshots at regular times from t = 0 to ``t_max``: a time,
    None (the whole run) or "settled" (until the shape stops changing,
    :func:`settling_index`; the whole run for a table without tilt and aspect ratio)."""
    times = trajectory["t"].to_numpy(float)
    if t_max == "settled":
        last = settling_index(trajectory) if {"theta_deg", "aspect_ratio"} <= set(trajectory) \
            else len(trajectory) - 1
        last = max(last, 1) if len(trajectory) > 1 else 0
    else:
        last = (len(trajectory) - 1 if t_max is None
                else int(np.searchsorted(times, t_max, "right") - 1))
    return np.unique(np.round(np.linspace(0, max(last, 0), snapshots)).astype(int))


def evolution(trajectory, snapshots=9, title="", fig=None, t_max="settled", t_range=None,
              colorbar=True):
    """Fig. 6: shape evolution of one run (trajectory table), centred on the centre of
    mass at each time: 3D view, side view (along x: y-z, the initial tilt plane edge-on)
    and top view (x-y), ``snapshots`` snapshots at regular times from t = 0 to ``t_max``
    (:func:`snapshot_indices`), coloured by time (light yellow first, dark purple last).
    ``t_range``: the colour range of time, (first, last) (default: 0 to the last time
    drawn).  ``fig``: a figure or subfigure to draw into (3 axes are added, and a colour
    bar when ``colorbar``); ``title`` becomes its suptitle."""
    if not len(trajectory):
        raise ValueError("the trajectory has no snapshots")
    if fig is None:
        fig = plt.figure(figsize=(10.0, 3.6), constrained_layout=True)
    grid = fig.add_gridspec(1, 3, width_ratios=(1.2, 1.0, 1.0))
    ax3d = fig.add_subplot(grid[0], projection="3d")
    side = fig.add_subplot(grid[1])
    top = fig.add_subplot(grid[2])
    times = trajectory["t"].to_numpy(float)
    index = snapshot_indices(trajectory, snapshots, t_max)
    cmap, norm = time_colours((times[0], times[index[-1]]) if t_range is None else t_range)
    for i in index:
        points = centred_curve(coefficients(trajectory["x"].iloc[i]))
        colour = cmap(norm(times[i]))
        ax3d.plot(points[0], points[1], points[2], color=colour, lw=1.2)
        side.plot(points[1], points[2], color=colour, lw=1.2)
        top.plot(points[0], points[1], color=colour, lw=1.2)
    lim = (-VIEW_LIMIT, VIEW_LIMIT)
    ax3d.set(xlim=lim, ylim=lim, zlim=lim, xticks=[-1, 0, 1], yticks=[-1, 0, 1], zticks=[-1, 0, 1])
    ax3d.set_xlabel("x", labelpad=-6, fontsize=9)
    ax3d.set_ylabel("y", labelpad=-6, fontsize=9)
    ax3d.set_zlabel("z", labelpad=-8, fontsize=9)
    ax3d.set_box_aspect((1, 1, 1))
    ax3d.tick_params(labelsize=7, pad=-2)
    side.set(xlabel="y (centred)", ylabel="z (centred)", title="side view (along x)",
             aspect="equal", xlim=lim, ylim=lim)
    top.set(xlabel="x (centred)", ylabel="y (centred)", title="top view (along z)",
            aspect="equal", xlim=lim, ylim=lim)
    for ax in (side, top):
        ax.title.set_fontsize(9)
    side.annotate("", xy=(1.45, -1.45), xytext=(1.45, -0.75),
                  arrowprops=dict(arrowstyle="-|>", color="k", lw=0.8))
    side.text(1.38, -1.1, "g", ha="right", va="center", fontsize=8)
    if colorbar:
        mappable = plt.cm.ScalarMappable(norm=norm, cmap=cmap)
        fig.colorbar(mappable, ax=[side, top], label="time t", shrink=0.85)
    if title:
        fig.suptitle(title, fontsize=11)
    return fig


def evolution_rows(trajectories, titles=None, snapshots=9, t_max="settled"):
    """Fig. 6 for several runs: one row of :func:`evolution` per trajectory table, all
    coloured on one time range (0 to the latest time any row draws) with one colour bar;
    each row's title ends with the times it draws."""
    trajectories = list(trajectories)
    if not trajectories:
        raise ValueError("no trajectories to draw")
    titles = list(titles) if titles is not None else [""] * len(trajectories)
    ends = [float(t["t"].to_numpy(float)[snapshot_indices(t, snapshots, t_max)[-1]])
            for t in trajectories]
    first, last = min(float(t["t"].iloc[0]) for t in trajectories), max(ends)
    fig = plt.figure(figsize=(10.4, 3.5 * len(trajectories)), layout="constrained")
    body, side = fig.subfigures(1, 2, width_ratios=[1.0, 0.11])
    rows = body.subfigures(len(trajectories), 1) if len(trajectories) > 1 else [body]
    for row, trajectory, title, end in zip(rows, trajectories, titles, ends):
        title = (f"{title}: " if title else "") + f"t = {trajectory['t'].iloc[0]:g} to {end:g}"
        evolution(trajectory, snapshots, title, fig=row, t_max=t_max, t_range=(first, last),
                  colorbar=False)
    cmap, norm = time_colours((first, last))
    grid = side.add_gridspec(5, 1)
    side.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), cax=side.add_subplot(grid[1:4]),
                  label="time t")
    return fig


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


def trajectory(frame, n=None, title="", axes=None):
    """Snapshots of one run (a trajectory table: columns t, x, theta_deg, aspect_ratio):
    left, the loop seen face-on (each snapshot, centred on its centre of mass, projected
    on the plane of the last snapshot's two largest principal axes) and coloured by time,
    with a colour bar; right, tilt and aspect ratio against time.

    Parameters
    ----------
    frame : pandas.DataFrame
        The trajectory table (``loopsim run --out``, ``storage.trajectory_table``).
    n : int, optional
        The order the snapshots are stored at (``n_used`` of an ``--n auto`` run, not its
        starting ``n``). None (default) reads it from the stored coefficients; a value
        that does not match them raises ValueError.
    title : str
        Drawn above the left panel.
    axes : pair of matplotlib axes, optional
        Where to draw; None makes a new figure.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if axes is None:
        fig, axes = plt.subplots(1, 2, figsize=(9.6, 3.9), constrained_layout=True)
    ax_shape, ax_time = axes
    s = np.linspace(0.0, 2.0 * np.pi, 200)
    times = frame["t"].to_numpy(float)
    cmap = plt.get_cmap("viridis_r")  # light yellow first, dark purple last (as the paper)
    norm = Normalize(vmin=times.min(), vmax=times.max() if times.max() > times.min() else times.min() + 1)
    shapes = [coefficients(c, n).copy() for c in frame["x"]]  # copies: centred below
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
