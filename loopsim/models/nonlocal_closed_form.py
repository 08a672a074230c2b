"""Nonlocal slender-body theory on the unit circle in closed form: the mode-by-mode action
of K and of the velocity operator, Johnson & Wu's (1979) rigid-ring mobilities, the
tilted ring's settling angle, and the first mode where the operator stops being positive.

Independent of the quadrature of ``nonlocal_operator`` (digamma closed forms, not
product integration): the tests check the operator against these.  Units and
conventions: those of ``nonlocal_operator``; derivations in docs/nonlocal.md.
"""
import math

import numpy as np
from scipy import special

from .nonlocal_operator import LOG_4_OVER_PI, slenderness_constant

def odd_harmonic_digamma(k):
    """h_k = [ψ(k + 1/2) - ψ(1/2)] / 2 (the closed form of :func:`odd_harmonic`)."""
    return 0.5 * (special.digamma(np.asarray(k, dtype=float) + 0.5) - special.digamma(0.5))


def circle_K_mode_matrix(k):
    """K on the unit circle x = (cos s, sin s, 0), mode e^{iks}, k ≥ 0, in the frame
    (t, n, b) = (x', x, e_z): K[e^{iks} (α_t t + α_n n + α_b b)] = e^{iks} (C α)·(t, n, b)
    with the Hermitian

        C = [[T_k, 3i a_k, 0], [-3i a_k, N_k, 0], [0, 0, B_k]],
        T_k = 4ℓ0 - 3(h_{k+1} + h_{|k-1|}) - 2h_k,   N_k = 2ℓ0 - 3(h_{k+1} + h_{|k-1|}) + 2h_k,
        B_k = 2ℓ0 - 4h_k,   a_k = h_{k+1} - h_{|k-1|} = 4k/(4k² - 1),   ℓ0 = log(4/π).

    Real modes: f = cos ks t gives T_k cos ks t + 3a_k sin ks n, and so on (docs/nonlocal.md).
    """
    if k < 0:
        raise ValueError("k must be >= 0")
    h = odd_harmonic_digamma
    pair = h(k + 1) + h(abs(k - 1))
    a = h(k + 1) - h(abs(k - 1))
    return np.array([[4 * LOG_4_OVER_PI - 3 * pair - 2 * h(k), 3j * a, 0.0],
                     [-3j * a, 2 * LOG_4_OVER_PI - 3 * pair + 2 * h(k), 0.0],
                     [0.0, 0.0, 2 * LOG_4_OVER_PI - 4 * h(k)]], dtype=complex)


def circle_velocity_mode_matrix(k, eps):
    """(1/c)(Λ + K) on mode k of the unit circle, frame (t, n, b): Λ = diag(2c-2, c+1, c+1)."""
    c = slenderness_constant(eps)
    return (np.diag([2 * c - 2, c + 1, c + 1]) + circle_K_mode_matrix(k)) / c


def johnson_wu_ring(eps):
    """Rigid-ring velocities per unit mean force density, loopsim units, from Johnson &
    Wu (1979) with ℓ = log(8R/a) = log(4/(π ε)):

    * broadside (along the axis): F = 8π²μRU / (ℓ + 1/2)  ->  U/g = (2ℓ + 1)/c;
    * edgewise (in the plane): F = 2π²μRU (3ℓ - 17/2) / [(ℓ - 1/2)(ℓ - 2) - 2]
      ->  U/g = 8 [(ℓ - 1/2)(ℓ - 2) - 2] / (c (3ℓ - 17/2)),

    with F = 2πR g and the velocity unit c g/(8πμ).  Returns (broadside, edgewise)."""
    c = slenderness_constant(eps)
    ell = math.log(4.0 / (math.pi * eps))
    broadside = (2.0 * ell + 1.0) / c
    edgewise = 8.0 * ((ell - 0.5) * (ell - 2.0) - 2.0) / (c * (3.0 * ell - 8.5))
    return broadside, edgewise


def settling_angle(eps=None):
    """(φ_max, θ*) in degrees: the largest angle between the rigid ring's velocity and
    gravity over its tilts, and the tilt θ* (axis from the vertical) reaching it.  With the
    ring's mobilities M_b (broadside) and M_e (edgewise), r = M_e / M_b,

        tan φ = (r − 1) sin θ cos θ / (cos² θ + r sin² θ),  largest at tan θ* = 1/√r:
        tan φ_max = (r − 1) / (2√r);

    ``eps`` None: the local model (M_b = 1, M_e = 4/3: φ_max = tan⁻¹(1/(4√3)) = 8.2132°,
    the paper's §4), else Johnson & Wu's mobilities (:func:`johnson_wu_ring`)."""
    if eps is None:
        ratio = 4.0 / 3.0
    else:
        broadside, edgewise = johnson_wu_ring(eps)
        ratio = edgewise / broadside
    phi = math.atan((ratio - 1.0) / (2.0 * math.sqrt(ratio)))
    return math.degrees(phi), math.degrees(math.atan(1.0 / math.sqrt(ratio)))


def first_nonpositive_mode(eps, k_max=10**15):
    """The smallest mode 1 ≤ k ≤ k_max at which (1/c)(Λ + K) on the circle has a
    non-positive eigenvalue (SBT's short-wave breakdown, k ≈ 0.108/ε), or None if there is
    none up to k_max: a truncation n of the nonlocal loop must stay below it.  The first
    eight modes one by one, then doubling and bisection (past its first modes the smallest
    eigenvalue falls like −log k; tested against a linear scan)."""
    def positive(k):
        return np.linalg.eigvalsh(circle_velocity_mode_matrix(k, eps)).min() > 0.0

    for k in range(1, min(8, k_max) + 1):
        if not positive(k):
            return k
    low = high = min(8, k_max)
    while positive(high):
        if high == k_max:
            return None
        low, high = high, min(2 * high, k_max)
    while high - low > 1:  # positive at low, not at high
        mid = (low + high) // 2
        low, high = (mid, high) if positive(mid) else (low, mid)
    return high
