"""Initial shapes: the inclined unit circle and its seeded perturbation.

The circle inclined at θ0 to the horizontal (paper §4)::

    x0(s) = [sin s, cos θ0 cos s, sin θ0 cos s]

with unit radial e_r = x0, tangent e_t = x0' and plane normal
e_n = [0, -sin θ0, cos θ0].

The perturbation of size ε (``perturbation``) is, exactly:

1. ``rng = numpy.random.default_rng(seed)``; ``Z = rng.standard_normal((n - 1, 4))``:
   row k - 2 holds (ζ cos, ζ sin, β cos, β sin) of mode k = 2..n, scaled by 1/k²
   (a smooth, spectrally decaying noise; modes 0 and 1 would be rigid motions).
   Rows are drawn mode by mode, so a mode's draw does not depend on n.
2. d(s) = ζ e_n - β' e_r + β e_t: an out-of-plane part ζ and an in-plane part
   that creates no length to first order (x0'·d' = 0), projected onto order n.
3. d is scaled so its root-mean-square amplitude ⟨|d|²⟩^½ over s equals ε.
4. x = x0 + d is scaled about its centre so that its length is exactly 2π.

With n = 1 there are no modes to perturb and the circle is returned as is.
"""
import numpy as np

from . import spectral

#: Quadrature points per unit of truncation order for lengths of initial shapes.
_LENGTH_POINTS_PER_ORDER = 64


def inclined_circle(n, theta0):
    """Coefficients (3, 2n+1) of the unit circle tilted by theta0 (radians)."""
    x = np.zeros((3, spectral.n_coeffs(n)))
    x[0, n + 1] = 1.0  # sin s
    x[1, 1] = np.cos(theta0)  # cos θ0 cos s
    x[2, 1] = np.sin(theta0)  # sin θ0 cos s
    return x


def curve_length(x, points=None):
    """L = ∫|x'| ds by the (spectrally accurate) periodic trapezoid rule."""
    n = spectral.order_of(x.shape[-1])
    m = points or _LENGTH_POINTS_PER_ORDER * (n + 1)
    dx = x @ spectral.synthesis_matrix(n, m, 1).T
    return 2.0 * np.pi * np.mean(np.linalg.norm(dx, axis=-2), axis=-1)


def rms_amplitude(c):
    """⟨|d|²⟩^½ over s of a vector series d with coefficients c (3, 2n+1)."""
    return np.sqrt(np.sum(c[:, 0] ** 2) + 0.5 * np.sum(c[:, 1:] ** 2))


def perturbation_field(n, theta0, seed):
    """Unit-RMS displacement d (3, 2n+1) defined in the module docstring."""
    if n < 2:
        return np.zeros((3, spectral.n_coeffs(n)))
    rng = np.random.default_rng(seed)
    k = np.arange(2, n + 1)
    z = (rng.standard_normal((n - 1, 4)) / k[:, None] ** 2).T
    # layout [a0, a1, a2..an, b1, b2..bn] with a0 = a1 = b1 = 0
    zeta = np.concatenate(([0.0, 0.0], z[0], [0.0], z[1]))
    beta = np.concatenate(([0.0, 0.0], z[2], [0.0], z[3]))
    m = 4 * n + 1
    s = spectral.grid(m)
    S0 = spectral.synthesis_matrix(n, m)
    S1 = spectral.synthesis_matrix(n, m, 1)
    e_r = np.stack([np.sin(s), np.cos(theta0) * np.cos(s), np.sin(theta0) * np.cos(s)])
    e_t = np.stack([np.cos(s), -np.cos(theta0) * np.sin(s), -np.sin(theta0) * np.sin(s)])
    e_n = np.array([0.0, -np.sin(theta0), np.cos(theta0)])[:, None]
    d = (S0 @ zeta) * e_n - (S1 @ beta) * e_r + (S0 @ beta) * e_t
    coeffs = d @ spectral.analysis_matrix(n, m).T
    return coeffs / rms_amplitude(coeffs)


def initial_shape(n, theta0, perturbation, seed):
    """Perturbed inclined circle of length exactly 2π (module docstring)."""
    x = inclined_circle(n, theta0)
    if perturbation > 0.0:
        x = x + perturbation * perturbation_field(n, theta0, seed)
        scale = 2.0 * np.pi / curve_length(x)
        x[:, 1:] *= scale
    return x
