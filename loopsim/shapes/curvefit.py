"""Closed curves through points: polygon checks and the arc-length Fourier fit.

:func:`fit_points` turns points on a closed curve (m, 3), in order, the last
not repeating the first, spacing free, into model coefficients:

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
0. Unit size.  The points are multiplied by a power of two (exact) that brings the
   largest |coordinate| into [0.5, 1), so that coordinates near 1e300 or 1e-300 fit as
   those near 1 do (the model is scale-free); lengths and the scale are reported in the
   file's units, and a file whose length or scale a double cannot hold is refused.
4. Scale and truncate.  g is truncated to order n (``spectral.resize``) and
   the whole shape (mean included) is multiplied by ``scale`` so its length
   is 2π: ``x_model = scale * x_file``; ``scale = 2π / L`` up to the length
   change of the truncation.  No rotation: gravity stays along -z of the file's
   frame.

Bad input raises a one-line ``ValueError``.
"""
import math

import numpy as np
from numpy.polynomial import legendre

from .. import diagnostics, spectral

#: Stencil size of the local polynomials that give the arc-length nodes.
STENCIL = 10
#: Gauss–Legendre points per segment for the local arc lengths.
GAUSS_POINTS = 8
#: Largest order of the periodic interpolant, and its largest condition number.
MAX_FIT_ORDER = 256
MAX_FIT_CONDITION = 100.0
#: Relative tolerances (to the polygon's length) for repeated points and crossings.
COINCIDENCE_TOL = 1e-10


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


def _weighted_fit(tau, points):
    """Least-squares trig polynomial (3, 2K+1) through the points at nodes tau."""
    m = tau.size
    weights = np.sqrt(((np.roll(tau, -1) - np.roll(tau, 1)) % (2.0 * np.pi)) / 2.0)

    def system(order):
        return spectral.basis(order, tau) * weights[:, None]

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


def unit_exponent(points, source="points"):
    """The power of two e that brings the largest |coordinate| of ``points`` into
    [0.5, 1): the fit works on ``points * 2**-e`` (exact: only the exponents change), since
    the model is scale-free (the shape is rescaled to length 2π) and squared distances of
    coordinates near 1e154 overflow, near 1e-160 underflow.  A one-line ValueError for
    coordinates that are all zero or subnormal (below 2.2e-308: too few digits left)."""
    largest = float(np.max(np.abs(points))) if points.size else 0.0
    if largest < np.finfo(float).tiny:
        raise ValueError(f"{source}: every coordinate is below {np.finfo(float).tiny:.3g} in "
                         f"size (largest {largest:.3g}): scale out of range, too few digits "
                         "left to fit a curve; scale the file's coordinates up")
    return math.frexp(largest)[1]


def _in_file_units(value, exponent, what, source):
    """``value * 2**exponent`` (a length or scale of the fit in the file's units), or a
    one-line ValueError where a double cannot hold it."""
    try:
        result = math.ldexp(value, exponent)
    except OverflowError:
        result = math.inf
    if not (math.isfinite(result) and result >= np.finfo(float).tiny):
        raise ValueError(f"{source}: scale out of range: the curve's {what} in the file's "
                         f"units ({value:.6g} x 2^{exponent}) is beyond what a double holds; "
                         "scale the file's coordinates towards 1")
    return result


def fit_points(points, n, source="points"):
    """Order-n coefficients (3, 2n+1) of the closed curve through ``points`` (m, 3), the
    fine arc-length series before truncation, and a dict of fit diagnostics (module doc).
    The points are first brought to unit size by a power of two (:func:`unit_exponent`),
    so that any finite scale fits alike; ``info``'s length and scale are in the file's
    units, ``fine`` is at that unit size (what it is used for, its modes' shares, is the
    same at any size)."""
    points = np.asarray(points, dtype=float)
    if points.ndim != 2 or points.shape[1] != 3:
        raise ValueError(f"{source}: points must have shape (m, 3), got {points.shape}")
    if not np.all(np.isfinite(points)):
        raise ValueError(f"{source}: non-finite coordinates")
    exponent = unit_exponent(points, source)
    points = np.ldexp(points, -exponent)
    check_points(points, n, source)
    tau, _ = _arc_length_nodes(points)
    f = _weighted_fit(tau, points)
    fit_order = spectral.order_of(f.shape[-1])
    residual = np.max(np.linalg.norm(spectral.evaluate(f, tau).T - points, axis=1))
    fine, length = _reparametrise(f, max(2 * fit_order, n))
    x = spectral.resize(fine, n)
    scale = 2.0 * np.pi / diagnostics.curve_length(x)
    x *= scale
    info = dict(kind="points", source=source, points=int(len(points)),
                length=_in_file_units(length, exponent, "length", source),
                scale=_in_file_units(scale, -exponent, "scale (2π over its length)", source),
                fit_order=int(fit_order), fit_residual=float(residual / length))
    return x, fine, info
