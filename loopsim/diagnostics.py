"""Diagnostics of a loop shape (plain NumPy, outside the hot loop), and their registry.

All shape functions take position coefficients x of shape (3, 2n+1)
(``spectral`` layout); angles are returned in degrees, as at the user
interface.  :data:`REGISTRY` lists the diagnostics of a state that feed the
run summary, the sweep table's columns and the trajectory table; adding one
there adds it to all three.
"""
import collections
import functools
import math

import numpy as np

from . import spectral
from .defaults import DEFORMATION_FLOOR

#: Fine grid points per unit of order for tension profiles and lengths.
PROFILE_POINTS_PER_ORDER = 64


def curve_length(x, points=None):
    """L = ∫|x'| ds by the (spectrally accurate) periodic trapezoid rule."""
    n = spectral.order_of(x.shape[-1])
    m = points or PROFILE_POINTS_PER_ORDER * (n + 1)
    dx = x @ spectral.synthesis_matrix(n, m, 1).T
    return 2.0 * np.pi * np.mean(np.linalg.norm(dx, axis=-2), axis=-1)


def rms_amplitude(c):
    """⟨|d|²⟩^½ over s of a vector series d with coefficients c (3, 2n+1)."""
    return np.sqrt(np.sum(c[:, 0] ** 2) + 0.5 * np.sum(c[:, 1:] ** 2))


def mode_energy(c):
    """E_k = ½ Σ_xyz (a_k² + b_k²) for k = 1..order (array of length order)."""
    c = np.asarray(c, dtype=float)
    order = spectral.order_of(c.shape[-1])
    return 0.5 * np.sum(c[:, 1 : order + 1] ** 2 + c[:, order + 1 :] ** 2, axis=0)


def spectral_tail(c, n):
    """Share of the deformation (modes k ≥ 2) carried by the top modes k ≥ max(2, n - 1):
    sqrt(Σ_{k ≥ max(2, n-1)} E_k / (Σ_{k ≥ 2} E_k + φ² Σ_{k ≥ 1} E_k)), φ the
    ``defaults.DEFORMATION_FLOOR`` (below it a loop counts as a circle)."""
    energy = mode_energy(c)
    scale = energy[1:].sum() + DEFORMATION_FLOOR**2 * energy.sum()
    return float(np.sqrt(energy[max(2, n - 1) - 1 :].sum() / scale)) if scale > 0 else 0.0


def top_mode_share(c, n):
    """RMS amplitude of the top modes k ≥ max(2, n - 1) relative to the loop's:
    sqrt(Σ_{k ≥ max(2, n-1)} E_k / Σ_{k ≥ 1} E_k) (the tail's absolute size)."""
    energy = mode_energy(c)
    total = energy.sum()
    return float(np.sqrt(energy[max(2, n - 1) - 1 :].sum() / total)) if total > 0 else 0.0


def truncation(c, n):
    """RMS relative amplitude in the modes k > n of the series c."""
    energy = mode_energy(c)
    total = energy.sum()
    return float(np.sqrt(energy[n:].sum() / total)) if total > 0 else 0.0


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


def tilts_and_aspect_ratios(xs):
    """:func:`tilt_deg` and :func:`aspect_ratio` of many shapes xs (K, 3, 2n+1) at once:
    two arrays (K,), NaN for a shape that is not finite (a time not reached)."""
    xs = np.asarray(xs, dtype=float)
    finite = np.all(np.isfinite(xs), axis=(1, 2))
    modes = np.where(finite[:, None, None], xs, 0.0)[:, :, 1:]
    values, vectors = np.linalg.eigh(0.5 * modes @ np.swapaxes(modes, 1, 2))
    with np.errstate(invalid="ignore", divide="ignore"):
        tilt = np.degrees(np.arccos(np.minimum(1.0, np.abs(vectors[:, 2, 0]))))
        aspect = values[:, 2] / values[:, 1]
    return np.where(finite, tilt, np.nan), np.where(finite, aspect, np.nan)


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


def stability_parameter(g0, theta_deg):
    """The stability parameter q = g0 sin θ / 3 of a loop tilted by θ (paper §4).

    Parameters
    ----------
    g0 : float
        Gravity over bending stiffness, L³ g ρ_L / (8π³ EI) (dimensionless).
    theta_deg : float
        Tilt of the loop's plane to the horizontal, in degrees.

    Returns
    -------
    float
        q (dimensionless): the translating circle loses stability in plane at
        q = 8.90 and out of plane at q = 10.65 (docs/stability.md).

    Raises
    ------
    TypeError
        ``g0`` or ``theta_deg`` is not a real number.

    Examples
    --------
    >>> import loopsim
    >>> round(loopsim.stability_parameter(150, 30), 6)
    25.0
    """
    return g0 * math.sin(math.radians(theta_deg)) / 3.0


# ---- the registry -----------------------------------------------------------------
class State:
    """A state: coefficients x (3, 2n+1), velocity u (3, 2n+1), tension multiplier
    (2n+1,), g0; with the quantities several diagnostics share, computed once."""

    def __init__(self, x, u, multiplier, g0):
        self.x, self.u, self.multiplier, self.g0 = x, u, multiplier, g0

    @functools.cached_property
    def tilt_deg(self):
        return tilt_deg(self.x)

    @functools.cached_property
    def tension_extremes(self):
        return tension_extremes(self.x, self.multiplier)


#: name: summary and sweep-table column; function(State) -> value; dtype: its Arrow/NumPy
#: type name; trajectory: its column in the trajectory table (None: summary only).
Diagnostic = collections.namedtuple("Diagnostic", "name function dtype trajectory doc")


def _tension(index):
    return lambda state: state.tension_extremes[index]


REGISTRY = [
    Diagnostic("theta_final_deg", lambda s: s.tilt_deg, "float64", "theta_deg",
               "tilt of the best-fit plane to the horizontal (deg)"),
    Diagnostic("q_final", lambda s: stability_parameter(s.g0, s.tilt_deg), "float64", None,
               "g0 sin(theta) / 3 at the final tilt"),
    Diagnostic("aspect_ratio", lambda s: aspect_ratio(s.x), "float64", "aspect_ratio",
               "largest / middle covariance eigenvalue"),
    Diagnostic("axis_ratio", lambda s: axis_ratio(s.x), "float64", None,
               "sqrt(aspect_ratio)"),
    Diagnostic("u_x", lambda s: float(s.u[0, 0]), "float64", None, "centre-of-mass velocity, x"),
    Diagnostic("u_y", lambda s: float(s.u[1, 0]), "float64", None, "centre-of-mass velocity, y"),
    Diagnostic("u_z", lambda s: float(s.u[2, 0]), "float64", None, "centre-of-mass velocity, z"),
    Diagnostic("settling_angle_deg", lambda s: settling_angle_deg(s.u[:, 0]), "float64", None,
               "angle between the centre-of-mass velocity and gravity (deg)"),
    Diagnostic("tension_max", _tension(0), "float64", "tension_max",
               "largest axial force N = T + |x''|^2"),
    Diagnostic("tension_min", _tension(1), "float64", "tension_min", "smallest axial force"),
    Diagnostic("s_tension_max", _tension(2), "float64", None, "arc length of the largest force"),
    Diagnostic("length_error", lambda s: relative_length_error(s.x), "float64", "length_error",
               "(L - 2 pi) / 2 pi"),
    Diagnostic("spectral_tail", lambda s: spectral_tail(s.x, spectral.order_of(s.x.shape[-1])),
               "float64", "spectral_tail",
               "RMS share of the deformation (modes k >= 2) in the two top modes kept "
               "(k >= max(2, n-1)): large means n too small"),
]


def evaluate(state, trajectory=False):
    """{name: value} of every registered diagnostic of ``state`` (``trajectory``: only
    those with a trajectory column, keyed by that column)."""
    if trajectory:
        return {d.trajectory: d.function(state) for d in REGISTRY if d.trajectory}
    return {d.name: d.function(state) for d in REGISTRY}
