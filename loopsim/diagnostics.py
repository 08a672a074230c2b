"""Diagnostics of a loop shape (plain NumPy, outside the hot loop).

All functions take position coefficients x of shape (3, 2n+1) (``spectral``
layout); angles are returned in degrees, as at the user interface.
"""
import numpy as np

from . import spectral
from .initial import curve_length

#: Fine grid points per unit of order for tension profiles and lengths.
PROFILE_POINTS_PER_ORDER = 64


def centre_of_mass(x):
    """(1/2π)∫x ds: the mean coefficient (arc-length weighted, |x'| = 1)."""
    return x[:, 0].copy()


def covariance(x):
    """C = (1/2π)∫(x - x̄)(x - x̄)ᵀ ds = ½ Σ_k (a_k a_kᵀ + b_k b_kᵀ)."""
    modes = x[:, 1:]
    return 0.5 * modes @ modes.T


def principal_axes(x):
    """Eigenvalues (ascending) and eigenvectors (columns) of the covariance."""
    return np.linalg.eigh(covariance(x))


def tilt_deg(x):
    """Angle between the best-fit plane and the horizontal, in [0, 90] degrees.

    The plane's normal is the eigenvector of the smallest covariance
    eigenvalue; the tilt is arccos |n_z|.
    """
    _, vectors = principal_axes(x)
    return float(np.degrees(np.arccos(min(1.0, abs(vectors[2, 0])))))


def aspect_ratio(x):
    """Paper's aspect ratio: largest / middle covariance eigenvalue (variances)."""
    values, _ = principal_axes(x)
    return float(values[2] / values[1])


def axis_ratio(x):
    """Ratio of the principal axes: the square root of :func:`aspect_ratio`."""
    return float(np.sqrt(aspect_ratio(x)))


def settling_angle_deg(u_com):
    """Angle between the centre-of-mass velocity and gravity (-z), in degrees."""
    return float(np.degrees(np.arctan2(np.hypot(u_com[0], u_com[1]), -u_com[2])))


def relative_length_error(x):
    """(L - 2π) / 2π, with L by a fine trapezoid rule."""
    return float(curve_length(x) / (2.0 * np.pi) - 1.0)


def tension_profile(x, multiplier, points=None):
    """Arc length s and physical axial force N(s) = T(s) + |x''(s)|².

    T is the Lagrange multiplier of the equations; N = n·x' with the internal
    force n = -x''' + T x' is the tension a user means (positive: stretched).
    On the translating circle N = q cos s (physics notes).
    """
    n = spectral.order_of(x.shape[-1])
    m = points or PROFILE_POINTS_PER_ORDER * (n + 1)
    s = spectral.grid(m)
    curvature = x @ spectral.synthesis_matrix(n, m, 2).T
    return s, spectral.evaluate(multiplier, s) + np.sum(curvature**2, axis=0)


def tension_extremes(x, multiplier):
    """(max N, min N, s at max N) on the fine profile grid."""
    s, force = tension_profile(x, multiplier)
    i = int(np.argmax(force))
    return float(force[i]), float(np.min(force)), float(s[i])
