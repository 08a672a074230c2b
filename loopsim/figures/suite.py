"""``loopsim figures``: read sweeps and run files and write every figure they allow as PNG."""
import os

import numpy as np
import pandas as pd

from .. import storage, validation
from ..stability.branch import steady_branch
from .evolution import evolution, evolution_rows, tension_figure
from .gallery import gallery
from .linear import stability, stability_data
from .phase import phase_diagram, phase_diagrams
from .style import orders_text, save as save_figure
from .terminal import aspect_ratio, q_and_tilt, seed_distributions

#: Figure names of :func:`write_figures` (``--only``), in drawing order.
FIGURE_NAMES = ("stability", "gallery", "phase", "q_tilt", "aspect", "phase_n", "seeds",
                "evolution", "tension")


def read_run(path):
    """(trajectory DataFrame, summary dict) of a ``loopsim run --out`` file, read as sweep
    chunks are (``storage.read_table_checked``: page checksums and content hash verified).
    ValueError, one line: a file that is not a run file, cannot be read, or is damaged
    (``'PATH' is damaged (...)``)."""
    from .. import storage

    try:
        meta = storage.read_metadata(path)
    except (OSError, ValueError) as exc:  # not Parquet, or a footer that does not decode
        raise ValueError(f"cannot read {path!r}: {str(exc).splitlines()[0]}") from None
    if "summary" not in meta:
        raise ValueError(f"cannot read {path!r}: not a run file (written by 'loopsim run "
                         "--out'): no run summary in its metadata")
    try:
        frame = storage.read_table_checked(path).to_pandas()
    except storage.DamagedFile as exc:  # a run file whose pages or content fail their checks
        raise ValueError(f"{exc}; run it again (loopsim run --out)") from None
    except OSError as exc:
        raise ValueError(f"cannot read {path!r}: {str(exc).splitlines()[0]}") from None
    missing = {"t", "x", "multiplier"} - set(frame.columns)
    if missing:
        raise ValueError(f"{path!r} is not a trajectory table (missing {sorted(missing)})")
    return frame, meta["summary"]


def read_sweep(path):
    """A sweep directory's table (``storage.read_results``); ValueError, one line, if it cannot
    be read or holds no finished case."""
    from .. import storage

    try:
        frame = storage.read_results(path)
    except (OSError, ValueError) as exc:
        raise ValueError(f"cannot read sweep {path!r}: {str(exc).splitlines()[0]}") from None
    if not len(frame):
        raise ValueError(f"sweep {path!r} holds no finished cases")
    return frame


def sweep_kind(frame):
    """'seeds' (some point has >= 3 seeds), 'grid' (a full g0 x θ0 product, >= 3 of each)
    or 'reference' (anything else: a list of cases)."""
    if frame.groupby(["g0", "theta0_deg", "n"]).size().max() >= 3:
        return "seeds"
    g0, theta0 = frame["g0"].nunique(), frame["theta0_deg"].nunique()
    points = len(frame[["g0", "theta0_deg"]].drop_duplicates())
    if g0 >= 3 and theta0 >= 3 and points == g0 * theta0:
        return "grid"
    return "reference"


def sweep_label(frame):
    """The orders and the method(s) of a table, for a legend: 'n = 6, rkf45'."""
    method = ("/".join(sorted(map(str, frame["method"].dropna().unique()))) if "method" in frame
              else (frame.attrs.get("loopsim", {}).get("sweep_config", {}) or {}).get("method"))
    return orders_text(frame) + (f", {method}" if method else "")


def run_title(summary):
    """'g0 = 150, θ0 = 60°, n = 16' (or 'n auto (n_used = 20)') from a run's summary."""
    used = summary.get("n_used", summary["n"])
    order = f"n = {summary['n']}" if used == summary["n"] else f"n auto (n_used = {used})"
    return f"g0 = {summary['g0']:g}, θ0 = {summary['theta0_deg']:.3g}°, {order}"


def write_figures(sweep_dir, others=(), out=".", only=None, gallery_theta0=30.0,
                  stability_n=16, branch_n=12, branch=True, dpi=110, log=print):
    """Draw every figure the inputs allow into ``out`` and return {name: path}.

    ``sweep_dir``: the main sweep (Figs. 4, 5, 7, 8).  ``others``: more sweep directories
    (a grid at another n: Fig. 9; several seeds of one point: the seed distributions;
    any other: a reference drawn over Figs. 7 and 8, and its own gallery) and run files
    (``loopsim run --out``: Fig. 6 and the tension colouring; Fig. 6 of one run is
    ``fig6_evolution_STEM``, of several runs one figure ``fig6_evolution``, a row per run
    in the order given, on one time scale).  Fig. 3 needs no input (``stability_n``: its
    truncation, and the largest n of its critical-q panel).  ``only``: a subset of
    :data:`FIGURE_NAMES`.  Bad input raises ValueError, before ``out`` (made if absent)
    is created or anything drawn.
    """
    only = _check_figure_options(only, dpi, gallery_theta0, branch_n, out)
    if not os.path.isdir(sweep_dir):
        raise ValueError(f"no sweep directory at {sweep_dir!r}")
    main = read_sweep(sweep_dir)
    sweeps, runs = _read_others(others)
    storage.make_directories(out)
    written = {}

    def save(name, fig):
        path = save_figure(fig, os.path.join(out, f"{name}.png"), dpi=dpi)
        written[name] = path
        log(f"{name}: {path}")

    _draw_sweep_figures(save, only, main, sweeps, gallery_theta0, stability_n,
                        branch_n if branch else None, log)
    _draw_run_figures(save, only, runs)
    return written


def _check_figure_options(only, dpi, gallery_theta0, branch_n, out):
    """The figure names asked for (a set), after :func:`write_figures`' options are
    checked; ValueError, one line, on the first that is not right."""
    only = set(FIGURE_NAMES if only is None else only)
    unknown = only - set(FIGURE_NAMES)
    if unknown:
        raise ValueError(f"unknown figure(s) {sorted(unknown)}; "
                         f"choose from {', '.join(FIGURE_NAMES)}")
    validation.check_count("dpi", dpi, 20, validation.MAX_DPI, "print quality; the pixel "
                           "count grows with its square")
    validation.check_tilt("gallery_theta0", gallery_theta0)
    validation.check_count("branch_n", branch_n, 4, validation.MAX_BRANCH_N,
                           "the continuation's cost grows like n^3 per point")
    validation.check_output_directory("out", out)
    return only


def _read_others(others):
    """The other sweeps by kind ({"grid", "seeds", "reference"}: [(path, frame)]) and the
    run files ([(path, trajectory, summary)]) of :func:`write_figures`' ``others``."""
    sweeps, runs = {"grid": [], "seeds": [], "reference": []}, []
    for path in others:
        if os.path.isdir(path):
            frame = read_sweep(path)
            sweeps[sweep_kind(frame)].append((path, frame))
        elif os.path.isfile(path):
            runs.append((path, *read_run(path)))
        else:
            raise ValueError(f"no such file or directory: {path!r}")
    return sweeps, runs


def _draw_sweep_figures(save, only, main, sweeps, gallery_theta0, stability_n, branch_n, log):
    """Figs. 3, 4, 5, 7, 8, 9 and the seed distributions, each through ``save(name, fig)``;
    ``branch_n`` None: Fig. 8 without the steady branch."""
    reference = (pd.concat([f for _, f in sweeps["reference"]], ignore_index=True)
                 if sweeps["reference"] else None)
    if "stability" in only:
        n_values = range(3, max(int(stability_n), 3) + 1)
        save("fig3_stability", stability(*stability_data(n=stability_n, n_values=n_values)))
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
        if branch_n is None:
            log("steady branch not requested")
        steady = None if branch_n is None else steady_branch(n=branch_n, q_max=25.0)
        save("fig8_aspect", aspect_ratio(main, steady, reference=reference, q_max=40.0))
    if "phase_n" in only and sweeps["grid"]:
        frames = sorted([f for _, f in sweeps["grid"]], key=lambda f: int(f["n"].min()))
        save("fig9_phase_n", phase_diagrams(frames))
    if "seeds" in only and sweeps["seeds"]:
        frames = [f for _, f in sweeps["seeds"]]
        save("seed_distributions", seed_distributions(frames, [sweep_label(f) for f in frames]))


def _draw_run_figures(save, only, runs):
    """Fig. 6 (one per run, or one of all runs) and Fig. 1 (per run) through ``save``."""
    if "evolution" in only and len(runs) > 1:
        save("fig6_evolution", evolution_rows([t for _, t, _ in runs],
                                              [run_title(s) for *_, s in runs]))
    for path, trajectory, summary in runs:
        stem = os.path.splitext(os.path.basename(path))[0]
        if "evolution" in only and len(runs) == 1:
            save(f"fig6_evolution_{stem}", evolution(trajectory, title=run_title(summary)))
        if "tension" in only:
            save(f"fig1_tension_{stem}",
                 tension_figure(trajectory, title=run_title(summary) + "\n"))
