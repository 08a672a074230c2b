"""The inclined unit circle, the seeded perturbation, and the perturbation of any shape.

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
:func:`perturb` applies the same recipe to any shape, in its own frame.
"""
import numpy as np

from .. import diagnostics, spectral
from ..defaults import DEFAULT_PERTURBATION



def inclined_circle(n, theta0):
    """Coefficients (3, 2n+1) of the unit circle tilted by theta0 (radians)."""
    x = np.zeros((3, spectral.n_coeffs(n)))
    x[0, n + 1] = 1.0  # sin s
    x[1, 1] = np.cos(theta0)  # cos θ0 cos s
    x[2, 1] = np.sin(theta0)  # sin θ0 cos s
    return x


def default_perturbation(given_shape):
    """The perturbation size used when none is given: DEFAULT_PERTURBATION for the
    tilted circle, 0 for a given shape (it is used as it is)."""
    return 0.0 if given_shape else DEFAULT_PERTURBATION


def seeded_modes(n, seed):
    """Coefficients (ζ, β), each (2n+1,), of the seeded draws of modes 2..n (module doc, step 1)."""
    rng = np.random.default_rng(seed)
    k = np.arange(2, n + 1)
    z = (rng.standard_normal((n - 1, 4)) / k[:, None] ** 2).T
    # layout [a0, a1, a2..an, b1, b2..bn] with a0 = a1 = b1 = 0
    zeta = np.concatenate(([0.0, 0.0], z[0], [0.0], z[1]))
    beta = np.concatenate(([0.0, 0.0], z[2], [0.0], z[3]))
    return zeta, beta


def frame_displacement(zeta, beta, normal, radial, tangent, m):
    """Coefficients of d = ζ e_n − β' e_r + β e_t (module doc, step 2) from grid values of
    the frame on the m-point grid, projected onto the order of ζ."""
    n = spectral.order_of(zeta.size)
    S0 = spectral.synthesis_matrix(n, m)
    S1 = spectral.synthesis_matrix(n, m, 1)
    d = (S0 @ zeta) * normal - (S1 @ beta) * radial + (S0 @ beta) * tangent
    return d @ spectral.analysis_matrix(n, m).T


def perturbation_field(n, theta0, seed):
    """Unit-RMS displacement d (3, 2n+1) defined in the module docstring."""
    if n < 2:
        return np.zeros((3, spectral.n_coeffs(n)))
    zeta, beta = seeded_modes(n, seed)
    m = 4 * n + 1
    s = spectral.grid(m)
    e_r = np.stack([np.sin(s), np.cos(theta0) * np.cos(s), np.sin(theta0) * np.cos(s)])
    e_t = np.stack([np.cos(s), -np.cos(theta0) * np.sin(s), -np.sin(theta0) * np.sin(s)])
    e_n = np.array([0.0, -np.sin(theta0), np.cos(theta0)])[:, None]
    coeffs = frame_displacement(zeta, beta, e_n, e_r, e_t, m)
    return coeffs / diagnostics.rms_amplitude(coeffs)


def initial_shape(n, theta0, perturbation, seed):
    """Perturbed inclined circle of length exactly 2π (module docstring)."""
    x = inclined_circle(n, theta0)
    if perturbation > 0.0:
        x = x + perturbation * perturbation_field(n, theta0, seed)
        scale = 2.0 * np.pi / diagnostics.curve_length(x)
        x[:, 1:] *= scale
    return x


def perturb(x, perturbation, seed):
    """x plus the seeded perturbation of RMS size ``perturbation`` in x's own frame.

    The recipe of :func:`perturbation_field` (same draws ζ, β of modes 2..n for a seed), with
    the circle's frame replaced by the shape's: tangent e_t = x'/|x'|, plane
    normal e_n (smallest covariance axis, n_z ≥ 0) and e_r = e_n × e_t; the sum is
    scaled about its centre back to the length of x.  For the inclined circle
    this is :func:`initial_shape` (to rounding).  n = 1 or a zero
    perturbation return x unchanged.
    """
    x = np.array(x, dtype=float)
    n = spectral.order_of(x.shape[-1])
    if perturbation == 0.0 or n < 2:
        return x
    zeta, beta = seeded_modes(n, seed)
    m = 2 * max(64, 8 * (n + 1)) + 1
    tangent = x @ spectral.synthesis_matrix(n, m, 1).T
    tangent /= np.linalg.norm(tangent, axis=0)
    _, axes = diagnostics.principal_axes(x)
    normal = axes[:, 0] * (-1.0 if axes[2, 0] < 0 else 1.0)
    radial = np.cross(normal[:, None], tangent, axis=0)
    d = frame_displacement(zeta, beta, normal[:, None], radial, tangent, m)
    d *= perturbation / diagnostics.rms_amplitude(d)
    out = x + d
    out[:, 1:] *= diagnostics.curve_length(x) / diagnostics.curve_length(out)
    return out
