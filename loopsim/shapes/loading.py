"""Initial shapes from files and from earlier results; one resolver for every entry point.

*Point files* (CSV or Parquet; columns ``x, y, z``, one row per point in
order along the closed curve) are fitted by ``shapes.curvefit``.  *Results*
(a ``loopsim run --out`` file, a sweep directory or one of its chunk files)
give the stored terminal coefficients of one case, used exactly
(``spectral.resize`` when another n is asked: exact when n ≥ the stored n).

Diagnostics (the ``info`` dict returned with every shape):

* ``tilt_deg``, ``aspect_ratio`` of the order-n shape (``diagnostics``);
* ``length``: the curve's length before rescaling (file units), ``scale``;
* ``spectral_tail`` (``diagnostics.top_mode_share``) of the fine shape (fitted
  order N, or the stored order of results): the RMS amplitude, relative to
  the loop's, carried by the two top modes kept and everything beyond n.
  Above :data:`TAIL_WARNING` (1e-3, the default perturbation's size) the
  shape is not resolved at this n and ``info["warnings"]`` says so;
* ``truncation``: the same ratio for the modes k > n only (what is lost).

:func:`start_shape` is the one place where a run's, a sweep case's or the
CLI's start is resolved: the tilted perturbed circle, or a given shape.
Bad input raises a one-line ``ValueError``.
"""
import functools
import math
import os

import numpy as np

from .. import diagnostics, spectral, storage, validation
from ..defaults import DEFAULT_N, INITIAL_CONTENT_TOL
from .tilted_circle import default_perturbation, initial_shape, perturb
from .curvefit import fit_points

#: RMS relative amplitude of the top modes above which a shape is flagged unresolved.
TAIL_WARNING = 1e-3
POINT_COLUMNS = ("x", "y", "z")


# ---- point files --------------------------------------------------------------
def _is_parquet(path):
    with open(path, "rb") as handle:
        return handle.read(4) == b"PAR1"


def _first_line(exc):
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__


def read_points(path):
    """Points (m, 3) of a CSV/Parquet point file (columns x, y, z; others ignored)."""
    import pandas as pd

    path = validation.check_input_file("initial shape file", os.fspath(path),
                                       validation.MAX_POINT_FILE_BYTES)
    limit = validation.MAX_POINTS
    try:
        if _is_parquet(path):
            import pyarrow.parquet as pq

            rows = pq.ParquetFile(path).metadata.num_rows
            frame = None if rows > limit else storage.read_table_checked(path).to_pandas()
        else:
            frame = pd.read_csv(path, nrows=limit + 1)
            rows = len(frame)
    except Exception as exc:  # noqa: BLE001 - any reader failure is the same user error
        raise ValueError(f"cannot read initial shape file {path!r}: {_first_line(exc)}") from None
    if rows > limit:
        raise ValueError(f"initial shape file {path!r} has more than {limit} points (the fit "
                         "checks every pair of segments: 10 000 points take about 80 s)")
    names = {str(c).strip().lower(): c for c in frame.columns}
    missing = [c for c in POINT_COLUMNS if c not in names]
    if missing:
        raise ValueError(f"initial shape file {path!r} lacks column(s) {missing} "
                         f"(needs x, y, z; has {[str(c) for c in frame.columns][:8]})")
    values = frame[[names[c] for c in POINT_COLUMNS]].apply(pd.to_numeric, errors="coerce")
    points = values.to_numpy(dtype=float)
    bad = np.argwhere(~np.isfinite(points))
    if bad.size:
        i, c = bad[0]
        raise ValueError(f"initial shape file {path!r}: non-finite or non-numeric "
                         f"{POINT_COLUMNS[c]} at point {i} (points counted from 0)")
    return points


def points_shape(points, n, source="points"):
    """Order-n shape through ``points`` (``curvefit.fit_points``) and its info, with
    ``content_order``: the order the fitted curve needs (:func:`content_order`)."""
    x, fine, info = fit_points(points, n, source)
    info.update(shape_info(x, fine, n), content_order=content_order(fine))
    return x, info


def content_order(fine, tol=INITIAL_CONTENT_TOL):
    """The lowest order m >= 1 whose truncation of the series ``fine`` leaves out at most
    ``tol`` of its RMS amplitude (``diagnostics.truncation``); fine's own order if none."""
    top = spectral.order_of(fine.shape[-1])
    return next((m for m in range(1, top) if diagnostics.truncation(fine, m) <= tol), top)


def auto_start_order(initial, case_id=None, low=DEFAULT_N, high=None):
    """The order a run with ``n="auto"`` starts a given shape at: for a point file, the
    order its content needs (``info["content_order"]``, :data:`defaults.INITIAL_CONTENT_TOL`)
    but not below ``low`` (the ladder's usual start) nor above ``high`` (its top); None for
    coefficients and results, which start at their stored order (exact)."""
    if not isinstance(initial, (str, os.PathLike)):
        return None
    _, info = load_initial(initial, None, case_id)
    if info["kind"] != "points":
        return None
    order = max(low, info["content_order"])
    return order if high is None else min(order, max(low, high))


# ---- diagnostics --------------------------------------------------------------
def shape_info(x, fine, n):
    """Diagnostics of the order-n shape x given its finer (or equal) series ``fine``."""
    info = dict(n=int(n), tilt_deg=diagnostics.tilt_deg(x),
                aspect_ratio=diagnostics.aspect_ratio(x),
                spectral_tail=diagnostics.top_mode_share(fine, n),
                truncation=diagnostics.truncation(fine, n))
    info["warnings"] = []
    if info["spectral_tail"] > TAIL_WARNING:
        info["warnings"].append(
            f"initial shape not resolved at n = {n}: the top modes carry "
            f"{info['spectral_tail']:.2g} of its RMS amplitude (> {TAIL_WARNING:g}); increase n")
    return info


def check_coefficients(x, source):
    """The order n of coefficients x (3, 2n+1); one-line ValueError for a bad shape or values."""
    x = np.asarray(x)
    if x.ndim != 2 or x.shape[0] != 3 or x.shape[1] % 2 != 1:
        raise ValueError(f"{source}: coefficients must have shape (3, 2n+1), got {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError(f"{source}: non-finite coefficients")
    return spectral.order_of(x.shape[1])


def _check_shape(x, source):
    x = np.asarray(x, dtype=float)
    check_coefficients(x, source)
    values = np.linalg.eigvalsh(diagnostics.covariance(x))
    if not values[1] > 1e-12 * max(values[2], np.finfo(float).tiny):
        raise ValueError(f"{source}: degenerate shape (a point or a line)")
    return x


def from_coefficients(x, n=None, source="coefficients"):
    """Shape (3, 2n+1) from coefficients of any order (exact when n ≥ their order), and info."""
    stored = _check_shape(x, source)
    n_stored = spectral.order_of(stored.shape[1])
    n = n_stored if n is None else n
    x = stored.copy() if n == n_stored else spectral.resize(stored, n)
    info = dict(kind="coefficients", source=source, n_stored=n_stored, scale=1.0,
                length=float(diagnostics.curve_length(stored)))
    info.update(shape_info(x, stored, n))
    return x, info


# ---- results ------------------------------------------------------------------
def _results_case(frame, source, case_id):
    """(coefficients, fields) of case ``case_id`` of a sweep results frame."""
    ids = frame["case_id"].tolist()
    if case_id is None:
        if len(ids) != 1:
            raise ValueError(f"{source} holds {len(ids)} cases: choose one with --case-id "
                             "(initial_case_id)")
        case_id = ids[0]
    if case_id not in ids:
        span = f"case ids {min(ids)}..{max(ids)}" if ids else "no finished cases"
        raise ValueError(f"case id {case_id} is not in the results {source!r} ({span})")
    row = frame.iloc[ids.index(case_id)]
    x = np.asarray(row["x_final"], dtype=float).reshape(3, -1)
    fields = dict(kind="sweep", case_id=int(case_id), g0=float(row["g0"]),
                  t_final=float(row["t_final"]), status=str(row["status"]))
    return x, fields


def _results_shape(path, case_id):
    """(coefficients, fields) from a results directory or file, or None for a point file."""
    import pyarrow.parquet as pq

    if os.path.isdir(path):
        return _results_case(storage.read_results(path), path, case_id)
    validation.check_input_file("initial shape file", path, validation.MAX_RESULTS_FILE_BYTES)
    if not _is_parquet(path):
        return None
    try:
        schema = pq.read_schema(path)
    except Exception as exc:  # noqa: BLE001
        raise ValueError(f"cannot read initial shape file {path!r}: {_first_line(exc)}") from None
    names = set(schema.names)
    if {"case_id", "x_final"} <= names:  # one chunk file of a sweep
        return _results_case(storage.read_table_checked(path).to_pandas(), path, case_id)
    if not {"t", "x"} <= names:
        return None
    table = storage.read_table_checked(path).select(
        [c for c in ("case_id", "t", "x") if c in names])
    rows = table.to_pandas()
    if "case_id" in names:  # a sweep's snapshots file
        ids = sorted(set(rows["case_id"]))
        if case_id is None and len(ids) == 1:
            case_id = ids[0]
        if case_id not in ids:
            raise ValueError(f"case id {case_id} is not in the results {path!r} "
                             f"(case ids {ids[:10]})")
        rows = rows[rows["case_id"] == case_id]
        summary = {}
    else:
        if case_id not in (None, 0):
            raise ValueError(f"case id {case_id} is not in the results {path!r} "
                             "(a single run: case 0)")
        summary = storage.read_metadata(path).get("summary", {})
        if not isinstance(summary, dict):
            summary = {}
    last = rows.iloc[int(np.argmax(rows["t"].to_numpy()))]
    x = np.asarray(last["x"], dtype=float).reshape(3, -1)
    fields = dict(kind="run", case_id=0 if case_id is None else int(case_id),
                  t_final=float(last["t"]))
    for key in ("g0", "status"):
        if key in summary:
            fields[key] = summary[key]
    return x, fields


def load_initial(path, n=None, case_id=None):
    """Initial shape (3, 2n+1) and info from a point file or from results.

    ``path``: a CSV/Parquet point file (fitted, see the module docstring), a
    ``loopsim run --out`` Parquet file (its last snapshot), a sweep directory
    or chunk file (case ``case_id``'s ``x_final``).  ``n``: truncation order
    (default: the stored order for results, ``DEFAULT_N`` for points).
    Results are used exactly when n ≥ the stored order (``scale`` = 1).
    """
    path = os.fspath(path)
    if n is not None:
        validation.check_order("n", n)
    if case_id is not None:
        validation.check_integer("case id", case_id, 0)
    if not os.path.exists(path):
        raise ValueError(f"cannot read initial shape {path!r}: no such file or directory")
    try:
        stat = os.stat(path)
        key = (os.path.abspath(path), stat.st_mtime_ns, stat.st_size,
               None if n is None else int(n), None if case_id is None else int(case_id))
        x, info = _load_cached(*key)
    except OSError as exc:
        raise ValueError(f"cannot read initial shape {path!r}: {_first_line(exc)}") from None
    info = dict(info, source=path, warnings=list(info["warnings"]))
    return x.copy(), info


@functools.lru_cache(maxsize=32)
def _load_cached(path, _mtime, _size, n, case_id):
    results = _results_shape(path, case_id)
    if results is None:
        if case_id is not None:
            raise ValueError(f"{path!r} is a point file: a case id applies only to results")
        return points_shape(read_points(path), DEFAULT_N if n is None else n, path)
    stored, fields = results
    x, info = from_coefficients(stored, n, path)
    info.update(fields)
    status = fields.get("status", "ok")
    if status != "ok":
        info["warnings"].append(f"case {fields['case_id']} of {path!r} ended with status "
                                f"{status!r}: its terminal shape is not a valid state")
    return x, info


def resolve_initial(initial, n=None, case_id=None):
    """``initial`` of ``api.simulate``: a path (:func:`load_initial`) or coefficients."""
    if isinstance(initial, (str, os.PathLike)):
        return load_initial(initial, n, case_id)
    if case_id is not None:
        raise ValueError("initial_case_id applies only when initial names a results file")
    return from_coefficients(initial, n)


# ---- sweep cases ------------------------------------------------------------------
def initial_case(case, source, case_id=None, base_dir="", perturbation_given=False):
    """A sweep case (dict) started from ``source``: tilt measured, perturbation 0 by default.

    ``source`` relative paths are taken relative to ``base_dir`` (the cases
    file's directory).  Adds ``initial``, ``initial_case_id`` (if any) and
    ``initial_scale`` to the case and sets ``theta0_deg`` to the measured tilt.
    """
    if case.get("theta0_deg") is not None and not math.isnan(case["theta0_deg"]):
        raise ValueError(f"a case with initial {source!r} has theta0_deg "
                         f"{case['theta0_deg']!r}: the tilt is measured from the shape, "
                         "leave it empty")
    path = source if os.path.isabs(source) else os.path.normpath(os.path.join(base_dir, source))
    _, info = load_initial(path, case["n"], case_id)
    case = dict(case, theta0_deg=info["tilt_deg"], initial=path, initial_scale=info["scale"])
    if case_id is not None:
        case["initial_case_id"] = int(case_id)
    if not perturbation_given:
        case["perturbation"] = 0.0
    return case


def start_shape(theta0_deg=None, n=None, perturbation=None, seed=0, initial=None,
                initial_case_id=None):
    """The start of a run, resolved in one place for ``simulate``, sweeps and the CLI.

    Without ``initial``: the circle tilted by ``theta0_deg`` (required) with the
    seeded perturbation (``tilted_circle.initial_shape``), n defaulting to DEFAULT_N.
    With ``initial`` (coefficients, or a path: :func:`load_initial`):
    ``theta0_deg`` must be None and becomes the shape's measured tilt, n
    defaults to the shape's order, and the perturbation (in the shape's own
    frame, ``tilted_circle.perturb``) defaults to 0.

    Returns (x0 (3, 2n+1), theta0_deg, n, perturbation, info); info is None for
    the circle, else the shape's diagnostics.
    """
    if n is not None:
        n = validation.check_order("n", n)
    perturbation = default_perturbation(initial is not None) if perturbation is None \
        else validation.check_perturbation("perturbation", perturbation)
    seed = validation.check_integer("seed", seed, 0)
    if initial is None:
        if initial_case_id is not None:
            raise ValueError("initial_case_id applies only when initial names a results file")
        if theta0_deg is None:
            raise ValueError("theta0_deg is required unless an initial shape is given")
        theta0_deg = validation.check_tilt("theta0_deg", theta0_deg)
        n = DEFAULT_N if n is None else n
        x0 = initial_shape(n, math.radians(theta0_deg), perturbation, seed)
        return x0, theta0_deg, n, perturbation, None
    if theta0_deg is not None:
        raise ValueError(f"theta0_deg must be None with an initial shape (its tilt is "
                         f"measured), got {theta0_deg!r}")
    start, info = resolve_initial(initial, n, initial_case_id)
    return perturb(start, perturbation, seed), info["tilt_deg"], info["n"], perturbation, info
