"""Animations of one run (``loopsim animate``): the loop falling, buckling and tilting.

Each frame is one *stored snapshot* of the run (a ``loopsim run --out`` file, or a sweep
case traced with ``--snapshots-for``); nothing is interpolated between snapshots, so a
smooth animation needs a run stored with many snapshots (``--snapshots 80``).  When a
run holds more snapshots than ``frames``, evenly spaced ones are drawn (the first and
the last always).

Left: the loop in 3D, in the frame falling with its centre of mass (each snapshot
centred on it), coloured by the axial force N = T + |x''|² with a colour bar centred at
N = 0 (one scale over the whole animation, saturating in the few frames of the largest
forces: :data:`COLOUR_PERCENTILE`), with its shadows on the floor (the
horizontal plane: the loop's outline seen from above) and on the back wall (the y-z
plane: the tilt of the loop's plane seen edge-on).  Right: the tilt θ and the aspect
ratio against time, a marker at the frame's time; the time stamp above.
"""
import os
import shutil

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import TwoSlopeNorm

from .. import diagnostics, render_defaults, spectral, validation
from .style import ASPECT_LABEL, coefficients

#: Default most frames drawn, frames per second and resolution, and their bounds
#: (``loopsim.render_defaults``, where ``loopsim animate --help`` reads them without NumPy).
FRAMES, FPS, DPI = (render_defaults.ANIMATION_FRAMES, render_defaults.ANIMATION_FPS,
                    render_defaults.ANIMATION_DPI)
MAX_FRAMES, MAX_FPS = render_defaults.ANIMATION_MAX_FRAMES, render_defaults.ANIMATION_MAX_FPS
MIN_DPI, MAX_DPI = render_defaults.ANIMATION_DPI_RANGE
#: Figure size in inches (width, height).
FIGSIZE = (8.4, 3.8)
#: File types written, by extension.
FORMATS = (".gif", ".mp4")
#: Points along the loop per frame.
POINTS = 160
#: The colour scale of the axial force spans ± this percentile of the frames' largest |N|
#: (a transient's few extreme frames saturate rather than wash out the others).
COLOUR_PERCENTILE = 80


def frame_indices(count, frames=FRAMES):
    """Indices of at most ``frames`` evenly spaced snapshots of ``count`` (first and last
    included; all of them when ``count <= frames``)."""
    if count <= frames:
        return np.arange(count)
    return np.unique(np.round(np.linspace(0, count - 1, frames)).astype(int))


def check_output(out):
    """``out`` as a path the animation can be written to: a .gif or .mp4 file in a
    writable directory, and for .mp4 ffmpeg on PATH.  ValueError (one line) otherwise.
    Nothing is created."""
    out = validation.check_output_file("--out", os.fspath(out))
    ext = os.path.splitext(out)[1].lower()
    if ext not in FORMATS:
        raise ValueError(f"--out {out!r}: an animation is a .gif or .mp4 file, got "
                         f"{ext or 'no extension'!r}")
    if ext == ".mp4" and shutil.which("ffmpeg") is None:
        raise ValueError(f"--out {out!r}: MP4 needs ffmpeg on PATH and there is none; write a "
                         f"GIF instead (--out {os.path.splitext(out)[0]}.gif)")
    return out


def _states(trajectory):
    """Per snapshot: (points (3, POINTS + 1) of the loop centred on its centre of mass,
    axial force N = T + |x''|² at the segments' midpoints (``diagnostics.tension_profile``))."""
    states = []
    for x_flat, m_flat in zip(trajectory["x"], trajectory["multiplier"]):
        x = coefficients(x_flat)
        s, force = diagnostics.tension_profile(x, np.asarray(m_flat, dtype=float), points=POINTS)
        s, force = np.append(s, 2.0 * np.pi), np.append(force, force[0])
        centred = x.copy()
        centred[:, 0] = 0.0
        states.append((spectral.evaluate(centred, s), 0.5 * (force[:-1] + force[1:])))
    return states


def _series(trajectory):
    """(t, tilt in degrees, aspect ratio) per snapshot: the stored columns, or measured."""
    t = trajectory["t"].to_numpy(float)
    if {"theta_deg", "aspect_ratio"} <= set(trajectory):
        return (t, trajectory["theta_deg"].to_numpy(float),
                trajectory["aspect_ratio"].to_numpy(float))
    shapes = [coefficients(x) for x in trajectory["x"]]
    return (t, np.array([diagnostics.tilt_deg(x) for x in shapes]),
            np.array([diagnostics.aspect_ratio(x) for x in shapes]))


def animation_figure(trajectory, title="", frames=FRAMES):
    """(figure, update, indices): the animation's figure at its first frame, the function
    ``update(k)`` that draws frame k, and the snapshot indices of the frames
    (:func:`frame_indices`).  ``trajectory``: a trajectory table (columns t, x,
    multiplier; theta_deg and aspect_ratio measured when absent)."""
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    if len(trajectory) < 2:
        raise ValueError(f"the run has {len(trajectory)} stored snapshot(s): an animation needs "
                         "at least 2 (store more: loopsim run --snapshots 80, or sweep "
                         "--snapshots 80 --snapshots-for K)")
    indices = frame_indices(len(trajectory), frames)
    rows = trajectory.iloc[indices].reset_index(drop=True)
    states = _states(rows)
    t, tilt, ratio = _series(rows)
    lim = 1.1 * max(float(np.abs(p).max()) for p, _ in states)
    peaks = [float(np.abs(f).max()) for _, f in states]
    bound = max(float(np.percentile(peaks, COLOUR_PERCENTILE)), 1e-12)
    norm = TwoSlopeNorm(vcenter=0.0, vmin=-bound, vmax=bound)

    fig = plt.figure(figsize=FIGSIZE, layout="constrained")
    grid = fig.add_gridspec(2, 2, width_ratios=(1.25, 1.0))
    ax3d = fig.add_subplot(grid[:, 0], projection="3d")
    ax_tilt = fig.add_subplot(grid[0, 1])
    ax_ratio = fig.add_subplot(grid[1, 1], sharex=ax_tilt)
    ax3d.set(xlim=(-lim, lim), ylim=(-lim, lim), zlim=(-lim, lim), xlabel="x", ylabel="y",
             zlabel="z (up)")
    ax3d.set_box_aspect((1, 1, 1))
    ax3d.tick_params(labelsize=6, pad=-2)
    ax3d.view_init(elev=18, azim=-60)
    lines = Line3DCollection([], cmap="RdBu_r", norm=norm, linewidths=2.5)
    ax3d.add_collection(lines)
    floor, = ax3d.plot([], [], [], color="0.6", lw=1.0)
    wall, = ax3d.plot([], [], [], color="0.75", lw=1.0, ls="--")
    fig.colorbar(lines, ax=ax3d, shrink=0.6, pad=0.14,
                 extend="both" if max(peaks) > bound else "neither",
                 label=r"axial force $N = T + |x''|^2$")
    ax3d.set_title("centred on the centre of mass; shadows on the floor and the y-z wall",
                   fontsize=7)
    ax_tilt.plot(t, tilt, color="C0", lw=1.2)
    ax_ratio.plot(t, ratio, color="C1", lw=1.2)
    tilt_marker, = ax_tilt.plot([], [], "o", color="C0", ms=6)
    ratio_marker, = ax_ratio.plot([], [], "o", color="C1", ms=6)
    cursors = [ax.axvline(t[0], color="0.6", lw=0.8) for ax in (ax_tilt, ax_ratio)]
    ax_tilt.set_ylabel("tilt θ (deg)", fontsize=8)
    ax_ratio.set_ylabel(ASPECT_LABEL, fontsize=7)
    ax_ratio.set_xlabel("time t", fontsize=8)
    for ax in (ax_tilt, ax_ratio):
        ax.tick_params(labelsize=7)
    plt.setp(ax_tilt.get_xticklabels(), visible=False)
    stamp = fig.suptitle("", fontsize=10)

    def update(k):
        points, force = states[k]
        xyz = points.T
        lines.set_segments(np.stack([xyz[:-1], xyz[1:]], axis=1))
        lines.set_array(force)
        floor.set_data_3d(points[0], points[1], np.full(points.shape[1], -lim))
        wall.set_data_3d(np.full(points.shape[1], -lim), points[1], points[2])
        tilt_marker.set_data([t[k]], [tilt[k]])
        ratio_marker.set_data([t[k]], [ratio[k]])
        for cursor in cursors:
            cursor.set_xdata([t[k], t[k]])
        stamp.set_text((f"{title}   " if title else "")
                       + f"t = {t[k]:.3f}   θ = {tilt[k]:.2f}°   aspect ratio = {ratio[k]:.3f}")
        return [lines, floor, wall, tilt_marker, ratio_marker, stamp, *cursors]

    update(0)
    return fig, update, indices


def write_animation(trajectory, out, title="", frames=FRAMES, fps=FPS, dpi=DPI):
    """Write the animation of a trajectory table (:func:`animation_figure`) to ``out``
    (.gif through Pillow, .mp4 through ffmpeg), atomically: a failed write leaves no file.
    Returns the number of frames written."""
    from matplotlib.animation import FFMpegWriter, FuncAnimation, PillowWriter

    from .. import storage

    out = check_output(out)
    frames = validation.check_count("--frames", frames, 2, MAX_FRAMES,
                                    "each frame is one image in the file")
    fps = validation.check_count("--fps", fps, 1, MAX_FPS, "frames per second")
    dpi = validation.check_count("--dpi", dpi, MIN_DPI, MAX_DPI, "the file grows as dpi²")
    fig, update, indices = animation_figure(trajectory, title, frames)
    try:
        movie = FuncAnimation(fig, update, frames=len(indices), blit=False)
        writer = (PillowWriter(fps=fps) if out.lower().endswith(".gif")
                  else FFMpegWriter(fps=fps))
        storage.write_file_atomically(out, lambda tmp: movie.save(tmp, writer=writer, dpi=dpi))
    finally:
        plt.close(fig)
    return len(indices)


def load_trajectory(source, case_id=None):
    """(trajectory table, title) of a run: ``source`` is a ``loopsim run --out`` file, a
    sweep directory with ``case_id`` (a case traced with ``--snapshots-for``), a
    ``SimulationResult`` or a trajectory DataFrame.  ValueError (one line) for a case
    that is not in the sweep or has no snapshots."""
    import pandas as pd

    from .. import storage
    from .suite import read_run, run_title

    if isinstance(source, pd.DataFrame):
        return source, ""
    if hasattr(source, "multiplier") and hasattr(source, "summary"):  # a SimulationResult
        return storage.trajectory_table(source).to_pandas(), run_title(source.summary())
    path = os.fspath(source)
    if os.path.isdir(path):
        if case_id is None:
            raise ValueError(f"{path!r} is a sweep directory: name the case with --case-id K "
                             "(one traced with --snapshots-for)")
        case_id = validation.check_integer("--case-id", case_id, 0)
        frame = storage.read_results(path)
        if case_id not in set(frame["case_id"].tolist()):
            raise ValueError(f"no finished case {case_id} in sweep {path!r} (its case ids: "
                             f"{int(frame['case_id'].min()) if len(frame) else '-'}.."
                             f"{int(frame['case_id'].max()) if len(frame) else '-'})")
        snapshots = storage.read_snapshots(path)
        if not len(snapshots) or case_id not in set(snapshots["case_id"].tolist()):
            raise ValueError(f"case {case_id} of sweep {path!r} has no snapshots: rerun it "
                             f"with --snapshots-for {case_id} --snapshots 80 (or run it "
                             "alone with loopsim run --out)")
        rows = snapshots[snapshots["case_id"] == case_id].reset_index(drop=True)
        row = frame[frame["case_id"] == case_id].iloc[0]
        summary = dict(g0=row["g0"], theta0_deg=row["theta0_deg"], n=row["n"],
                       n_used=row["n_used"])
        return rows, f"case {case_id}: {run_title(summary)}"
    if case_id is not None:
        raise ValueError(f"--case-id {case_id} names a case of a sweep directory; "
                         f"{path!r} is not one")
    if not os.path.isfile(path):
        raise ValueError(f"no run file or sweep directory at {path!r}")
    frame, summary = read_run(path)
    return frame, run_title(summary)


def animate(source, out, case_id=None, frames=FRAMES, fps=FPS, dpi=DPI):
    """Animate one run into a GIF or MP4 file.

    Each frame shows the loop in 3D, centred on its centre of mass and coloured by the
    axial force N = T + |x''|², with its shadows on the floor and on the y-z wall, beside
    the tilt and the aspect ratio against time with a marker at the frame's time (see
    the module docstring).  The frames are the run's stored snapshots: nothing is
    interpolated between them.

    Parameters
    ----------
    source : str, os.PathLike, SimulationResult or pandas.DataFrame
        A run file (``loopsim run --out``), a sweep directory (with ``case_id``), a
        ``SimulationResult`` (``loopsim.simulate``) or a trajectory table (columns
        ``t``, ``x``, ``multiplier``).
    out : str or os.PathLike
        The file to write: ``.gif`` (Pillow) or ``.mp4`` (needs ffmpeg on PATH).
    case_id : int or None, default None
        With a sweep directory: the case, recorded with ``--snapshots-for``.
    frames : int, default 60
        Most frames (2 to 600): evenly spaced stored snapshots, first and last included;
        every snapshot when the run has fewer.
    fps : int, default 10
        Frames per second (1 to 60).
    dpi : int, default 80
        Dots per inch of the 8.4 x 3.8 inch frames (30 to 200; 80 gives 672 x 304 pixels).

    Returns
    -------
    int
        The number of frames written.

    Raises
    ------
    ValueError
        One line, before anything is written: an output that is not a writable .gif or
        .mp4 path (an .mp4 without ffmpeg names the .gif instead), an option out of
        bounds, a sweep case that is not there or has no snapshots, a run with fewer
        than 2 snapshots.  The file is written atomically: a failed write leaves none.

    Examples
    --------
    A run stored with 121 snapshots (``loopsim run ... --snapshots 121 --out
    runs/3d.parquet``), drawn as 60 of them:

    >>> import loopsim
    >>> loopsim.animate("runs/3d.parquet", "runs/3d.gif")  # doctest: +SKIP
    60
    >>> loopsim.animate("runs/phase", "case7.gif", case_id=7, frames=30)  # doctest: +SKIP
    30
    """
    check_output(out)
    trajectory, title = load_trajectory(source, case_id)
    return write_animation(trajectory, out, title, frames=frames, fps=fps, dpi=dpi)
