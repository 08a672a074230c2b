"""Initial shapes from files: point tables and earlier results.

A *point file* (CSV or Parquet) holds points on a closed curve, columns
``x, y, z``, one row per point, in order along the curve, the last point not
repeating the first; spacing may be uneven.  :func:`fit_points` turns it into
model coefficients:

1. Arc-length nodes.  Each point gets the arc length τ_j from the first point
   along the curve: the length of every segment j → j+1 is the length of the
   local degree-9 polynomial through the 10 nearest points (parameter: the
   current τ, Gauss–Legendre quadrature), iterated from the chord lengths
   until τ changes by less than 1e-13 (3–4 iterations on smooth data; high
   order, so nodes of a smooth curve land on their arc length to ~1e-14).
2. Periodic interpolant.  A trigonometric polynomial f(τ) of order K is fitted
   to the points at the nodes by least squares weighted by the local spacing,
   K the largest order ≤ (m - 1) / 2 (and ≤ 256) whose weighted system has
   condition number ≤ 100, i.e. interpolation for reasonably spaced points.
3. Arc length.  The speed |f'| is expanded in a fine Fourier series and
   integrated exactly; σ(τ) is inverted by Newton's method at equispaced arc
   length and f is resampled there: the fine shape g(s) of order N = max(2K, n)
   is parametrised by arc length starting from the first point.
4. Scale and truncate.  g is truncated to order n (``spectral.resize``) and
   the whole shape (mean included) is multiplied by ``scale`` so its length
   is 2π: ``x_model = scale * x_file``; ``scale = 2π / L`` up to the length
   change of the truncation.  No rotation: gravity stays along -z of the file's
   frame.

*Results* (a ``loopsim run --out`` file, a sweep directory or one of its chunk
files) give the stored terminal coefficients of one case, used exactly
(``spectral.resize`` when another n is asked: exact when n ≥ the stored n).

Diagnostics (the ``info`` dict returned with every shape):

* ``tilt_deg``, ``aspect_ratio`` of the order-n shape (``diagnostics``);
* ``length``: the curve's length before rescaling (file units), ``scale``;
* ``spectral_tail``: with E_k = ½ Σ_xyz (a_k² + b_k²) the energy of mode k ≥ 1
  of the fine shape (fitted order N, or the stored order of results),
  ``sqrt(Σ_{k ≥ max(2, n-1)} E_k / Σ_{k ≥ 1} E_k)``: the RMS amplitude, relative
  to the loop's, carried by the two top modes kept and everything beyond n.
  Above :data:`TAIL_WARNING` (1e-3, the default perturbation's size) the
  shape is not resolved at this n and ``info["warnings"]`` says so;
* ``truncation``: the same ratio for the modes k > n only (what is lost).

Bad input raises a one-line ``ValueError``.
"""
import functools
import math
import os

import numpy as np
from numpy.polynomial import legendre

from . import diagnostics, spectral
from .config import DEFAULT_N

#: RMS relative amplitude of the top modes above which a shape is flagged unresolved.
TAIL_WARNING = 1e-3
#: Stencil size of the local polynomials that give the arc-length nodes.
STENCIL = 10
#: Gauss–Legendre points per segment for the local arc lengths.
GAUSS_POINTS = 8
#: Largest order of the periodic interpolant, and its largest condition number.
MAX_FIT_ORDER = 256
MAX_FIT_CONDITION = 100.0
#: Relative tolerances (to the polygon's length) for repeated points and crossings.
COINCIDENCE_TOL = 1e-10
POINT_COLUMNS = ("x", "y", "z")


# ---- reading --------------------------------------------------------------
def _is_parquet(path):
    with open(path, "rb") as handle:
        return handle.read(4) == b"PAR1"


def _first_line(exc):
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__


def read_points(path):
    """Points (m, 3) of a CSV/Parquet point file (columns x, y, z; others ignored)."""
    import pandas as pd

    path = os.fspath(path)
    try:
        frame = pd.read_parquet(path) if _is_parquet(path) else pd.read_csv(path)
    except Exception as exc:  # noqa: BLE001 - any reader failure is the same user error
        raise ValueError(f"cannot read initial shape file {path!r}: {_first_line(exc)}") from None
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


def check_points(points, n, source="points"):
    """One-line ValueError for too few, repeated, collinear or self-intersecting points."""
    m = len(points)
    need = max(3, spectral.n_coeffs(n))
    if m < need:
        raise ValueError(f"{source}: {m} points, but order n = {n} needs at least {need}")
    if not np.all(np.isfinite(points)):
        raise ValueError(f"{source}: non-finite coordinates")
    segments = np.roll(points, -1, axis=0) - points
    length = float(np.sum(np.linalg.norm(segments, axis=1)))
    tol = COINCIDENCE_TOL * length
    from scipy.spatial import cKDTree

    pairs = sorted(cKDTree(points).query_pairs(max(tol, np.finfo(float).tiny)))
    if length == 0.0 or pairs:
        i, j = pairs[0] if pairs else (0, 1)
        if (i, j) == (0, m - 1):
            raise ValueError(f"{source}: the last point repeats the first (the curve is closed "
                             "implicitly: drop the last row)")
        raise ValueError(f"{source}: points {i} and {j} coincide (repeated point)")
    centred = points - points.mean(axis=0)
    sv = np.linalg.svd(centred, compute_uv=False)
    if sv[1] <= 1e-9 * sv[0]:
        raise ValueError(f"{source}: degenerate curve (all points collinear)")
    hit = _first_crossing(points, segments, tol)
    if hit is not None:
        i, j = hit
        raise ValueError(f"{source}: self-intersecting curve (segment {i}-{(i + 1) % m} meets "
                         f"segment {j}-{(j + 1) % m})")


def _segment_distance(p, d, q, e):
    """Distances between segments p + s d and q + t e, s, t ∈ [0, 1] (broadcast, Ericson)."""
    r = p - q
    a, b, c = np.sum(d * d, -1), np.sum(d * e, -1), np.sum(d * r, -1)
    ee, f = np.sum(e * e, -1), np.sum(e * r, -1)
    denom = a * ee - b * b
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(denom > 1e-14 * a * ee, np.clip((b * f - c * ee) / denom, 0.0, 1.0), 0.0)
        t = (b * s + f) / ee
        s = np.where(t < 0.0, np.clip(-c / a, 0.0, 1.0),
                     np.where(t > 1.0, np.clip((b - c) / a, 0.0, 1.0), s))
    t = np.clip(t, 0.0, 1.0)
    return np.linalg.norm(r + s[..., None] * d - t[..., None] * e, axis=-1)


def _first_crossing(points, segments, tol, block=256):
    """First pair (i, j) of non-adjacent polygon segments closer than tol, or None."""
    m = len(points)
    j = np.arange(m)
    for start in range(0, m, block):
        i = np.arange(start, min(m, start + block))[:, None]
        gap = (j[None, :] - i) % m
        dist = _segment_distance(points[i], segments[i], points[None, j], segments[None, j])
        dist = np.where((j[None, :] > i) & (gap != 1) & (gap != m - 1), dist, np.inf)
        close = np.argwhere(dist < tol)
        if close.size:
            return int(i[close[0, 0], 0]), int(close[0, 1])
    return None


# ---- fitting ----------------------------------------------------------------
def _arc_length_nodes(points, iterations=30, tol=1e-13):
    """Arc length τ_j (scaled to [0, 2π)) of each point from the first, and the length."""
    m = len(points)
    q = min(STENCIL, m - m % 2)
    offsets = np.arange(q) - (q // 2 - 1)  # stencil j - q/2 + 1 .. j + q/2 around segment j
    index = np.arange(m)[:, None] + offsets
    stencil = points[index % m]
    wraps = np.floor_divide(index, m)
    xg, wg = legendre.leggauss(GAUSS_POINTS)
    derivative = np.zeros((q, q))
    for k in range(q):
        unit = np.zeros(q)
        unit[k] = 1.0
        dk = legendre.legder(unit)
        derivative[: dk.size, k] = dk
    chords = np.linalg.norm(np.roll(points, -1, axis=0) - points, axis=1)
    lengths = chords
    tau = 2.0 * np.pi * np.concatenate(([0.0], np.cumsum(chords)[:-1])) / chords.sum()
    change = math.inf
    for _ in range(iterations):
        t = tau[index % m] + 2.0 * np.pi * wraps
        half = 0.5 * ((np.roll(tau, -1) - tau) % (2.0 * np.pi))
        mid = tau + half
        width = half * q / 2.0
        u = (t - mid[:, None]) / width[:, None]
        coef = np.linalg.solve(legendre.legvander(u, q - 1), stencil)  # (m, q, 3)
        ug = xg[None, :] * half[:, None] / width[:, None]
        speed_basis = legendre.legvander(ug, q - 1) @ derivative  # (m, g, q)
        velocity = np.einsum("mgq,mqc->mgc", speed_basis, coef) / width[:, None, None]
        lengths = (np.linalg.norm(velocity, axis=-1) @ wg) * half
        new = 2.0 * np.pi * np.concatenate(([0.0], np.cumsum(lengths)[:-1])) / lengths.sum()
        if not np.all(np.diff(new) > 0):
            break  # the local interpolants fold back: keep the previous nodes
        new_change = float(np.max(np.abs(new - tau)))
        tau = new
        if new_change < tol or new_change >= change:
            break
        change = new_change
    return tau, float(lengths.sum())


def _basis(tau, order):
    k = np.arange(1, order + 1)
    return np.concatenate(
        (np.ones((tau.size, 1)), np.cos(np.outer(tau, k)), np.sin(np.outer(tau, k))), axis=1)


def _weighted_fit(tau, points):
    """Least-squares trig polynomial (3, 2K+1) through the points at nodes tau."""
    m = tau.size
    weights = np.sqrt(((np.roll(tau, -1) - np.roll(tau, 1)) % (2.0 * np.pi)) / 2.0)

    def system(order):
        return _basis(tau, order) * weights[:, None]

    def condition(order):  # from the normal matrix: cheaper than an SVD, fine up to ~1e7
        values = np.linalg.eigvalsh(system(order).T @ system(order))
        return math.sqrt(values[-1] / values[0]) if values[0] > 0 else math.inf

    order = min((m - 1) // 2, MAX_FIT_ORDER)
    if condition(order) > MAX_FIT_CONDITION:
        low, high = 1, order  # condition(low) is ~1.4: bisect for the largest good order
        while high - low > 1:
            mid = (low + high) // 2
            low, high = (mid, high) if condition(mid) <= MAX_FIT_CONDITION else (low, mid)
        order = low
    coeffs, *_ = np.linalg.lstsq(system(order), points * weights[:, None], rcond=None)
    return coeffs.T


def _fft_fit(values):
    """``spectral.fit`` by FFT: coefficients of order (m - 1) // 2 of m grid values (last axis)."""
    m = values.shape[-1]
    order = (m - 1) // 2
    spectrum = np.fft.rfft(values, axis=-1)[..., : order + 1] / m
    return np.concatenate((spectrum[..., :1].real, 2.0 * spectrum[..., 1:].real,
                           -2.0 * spectrum[..., 1:].imag), axis=-1)


def _speed_series(c):
    """Fine Fourier coefficients of |f'| for a series c (3, 2K+1)."""
    order = spectral.order_of(c.shape[-1])
    grid_points = 2 * max(512, 8 * (order + 1)) + 1
    velocity = c @ spectral.synthesis_matrix(order, grid_points, 1).T
    return _fft_fit(np.linalg.norm(velocity, axis=0))


def _arc_length_at(speed, tau):
    """σ(τ) = ∫_0^τ |f'| from the speed series (exact antiderivative)."""
    order = spectral.order_of(speed.size)
    k = np.arange(1, order + 1)
    a, b = speed[1 : order + 1] / k, speed[order + 1 :] / k
    return speed[0] * tau + np.sin(np.outer(tau, k)) @ a + (1.0 - np.cos(np.outer(tau, k))) @ b


def _reparametrise(c, order):
    """f (3, 2K+1) resampled at equispaced arc length: coefficients of order ``order``, length."""
    speed = _speed_series(c)
    length = 2.0 * np.pi * speed[0]
    points = spectral.n_coeffs(order)
    target = spectral.grid(points) * speed[0]  # σ values, [0, L)
    tau = spectral.grid(points)
    for _ in range(50):
        step = (_arc_length_at(speed, tau) - target) / spectral.evaluate(speed, tau)
        tau -= step
        if np.max(np.abs(step)) < 1e-15:
            break
    return _fft_fit(spectral.evaluate(c, tau)), float(length)


def fit_points(points, n, source="points"):
    """Order-n coefficients (3, 2n+1) of the closed curve through ``points`` (m, 3), and info.

    See the module docstring for the method and the info fields.
    """
    points = np.asarray(points, dtype=float)
    if points.ndim != 2 or points.shape[1] != 3:
        raise ValueError(f"{source}: points must have shape (m, 3), got {points.shape}")
    check_points(points, n, source)
    tau, _ = _arc_length_nodes(points)
    f = _weighted_fit(tau, points)
    fit_order = spectral.order_of(f.shape[-1])
    residual = np.max(np.linalg.norm(spectral.evaluate(f, tau).T - points, axis=1))
    fine, length = _reparametrise(f, max(2 * fit_order, n))
    x = spectral.resize(fine, n)
    scale = 2.0 * np.pi / diagnostics.curve_length(x)
    x *= scale
    info = dict(kind="points", source=source, points=int(len(points)), length=length,
                scale=float(scale), fit_order=int(fit_order),
                fit_residual=float(residual / length))
    info.update(shape_info(x, fine, n))
    return x, info


# ---- diagnostics --------------------------------------------------------------
def mode_energy(c):
    """E_k = ½ Σ_xyz (a_k² + b_k²) for k = 1..order (array of length order)."""
    c = np.asarray(c, dtype=float)
    order = spectral.order_of(c.shape[-1])
    return 0.5 * np.sum(c[:, 1 : order + 1] ** 2 + c[:, order + 1 :] ** 2, axis=0)


def spectral_tail(c, n):
    """RMS relative amplitude in the modes k ≥ max(2, n - 1) of the series c (module doc)."""
    energy = mode_energy(c)
    total = energy.sum()
    return float(np.sqrt(energy[max(2, n - 1) - 1 :].sum() / total)) if total > 0 else 0.0


def truncation(c, n):
    """RMS relative amplitude in the modes k > n of the series c."""
    energy = mode_energy(c)
    total = energy.sum()
    return float(np.sqrt(energy[n:].sum() / total)) if total > 0 else 0.0


def shape_info(x, fine, n):
    """Diagnostics of the order-n shape x given its finer (or equal) series ``fine``."""
    info = dict(n=int(n), tilt_deg=diagnostics.tilt_deg(x),
                aspect_ratio=diagnostics.aspect_ratio(x),
                spectral_tail=spectral_tail(fine, n), truncation=truncation(fine, n))
    info["warnings"] = []
    if info["spectral_tail"] > TAIL_WARNING:
        info["warnings"].append(
            f"initial shape not resolved at n = {n}: the top modes carry "
            f"{info['spectral_tail']:.2g} of its RMS amplitude (> {TAIL_WARNING:g}); increase n")
    return info


def _check_shape(x, source):
    x = np.asarray(x, dtype=float)
    if x.ndim != 2 or x.shape[0] != 3 or x.shape[1] % 2 != 1:
        raise ValueError(f"{source}: coefficients must have shape (3, 2n+1), got {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError(f"{source}: non-finite coefficients")
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
        from .ensemble import read_results

        return _results_case(read_results(path), path, case_id)
    if not _is_parquet(path):
        return None
    try:
        schema = pq.read_schema(path)
    except Exception as exc:  # noqa: BLE001
        raise ValueError(f"cannot read initial shape file {path!r}: {_first_line(exc)}") from None
    names = set(schema.names)
    if {"case_id", "x_final"} <= names:  # one chunk file of a sweep
        return _results_case(pq.read_table(path).to_pandas(), path, case_id)
    if not {"t", "x"} <= names:
        return None
    from . import io

    table = pq.read_table(path, columns=[c for c in ("case_id", "t", "x") if c in names])
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
        summary = io.read_metadata(path).get("summary", {})
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
    if n is not None and (isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1):
        raise ValueError(f"n must be an integer >= 1, got {n!r}")
    if case_id is not None and (isinstance(case_id, bool)
                                or not isinstance(case_id, (int, np.integer)) or case_id < 0):
        raise ValueError(f"case id must be an integer >= 0, got {case_id!r}")
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
        return fit_points(read_points(path), DEFAULT_N if n is None else n, path)
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


# ---- perturbation ---------------------------------------------------------------
def perturb(x, perturbation, seed):
    """x plus the seeded perturbation of RMS size ``perturbation`` in x's own frame.

    The recipe of ``initial`` (same draws ζ, β of modes 2..n for a seed), with
    the circle's frame replaced by the shape's: tangent e_t = x'/|x'|, plane
    normal e_n (smallest covariance axis, n_z ≥ 0) and e_r = e_n × e_t; the sum is
    scaled about its centre back to the length of x.  For the inclined circle
    this is ``initial.initial_shape`` (to rounding).  n = 1 or a zero
    perturbation return x unchanged.
    """
    x = np.array(x, dtype=float)
    n = spectral.order_of(x.shape[-1])
    if perturbation == 0.0 or n < 2:
        return x
    rng = np.random.default_rng(seed)
    k = np.arange(2, n + 1)
    z = (rng.standard_normal((n - 1, 4)) / k[:, None] ** 2).T
    zeta = np.concatenate(([0.0, 0.0], z[0], [0.0], z[1]))
    beta = np.concatenate(([0.0, 0.0], z[2], [0.0], z[3]))
    m = 2 * max(64, 8 * (n + 1)) + 1
    tangent = x @ spectral.synthesis_matrix(n, m, 1).T
    tangent /= np.linalg.norm(tangent, axis=0)
    _, axes = diagnostics.principal_axes(x)
    normal = axes[:, 0] * (-1.0 if axes[2, 0] < 0 else 1.0)
    radial = np.cross(normal[:, None], tangent, axis=0)
    d = ((spectral.synthesis_matrix(n, m) @ zeta) * normal[:, None]
         - (spectral.synthesis_matrix(n, m, 1) @ beta) * radial
         + (spectral.synthesis_matrix(n, m) @ beta) * tangent)
    d = d @ spectral.analysis_matrix(n, m).T
    d *= perturbation / np.sqrt(np.sum(d[:, 0] ** 2) + 0.5 * np.sum(d[:, 1:] ** 2))
    out = x + d
    out[:, 1:] *= diagnostics.curve_length(x) / diagnostics.curve_length(out)
    return out


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


def case_shape(case):
    """Start shape of a sweep case made by :func:`initial_case`."""
    x, _ = load_initial(case["initial"], case["n"], case.get("initial_case_id"))
    return perturb(x, case["perturbation"], case["seed"])
