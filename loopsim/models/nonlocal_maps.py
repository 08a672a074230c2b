"""Nonlocal slender-body theory on a closed loop: the compiled kernels of its operator K.

The plain-NumPy reference, its derivation and its checks against closed forms are
``models.nonlocal_operator`` (docs/nonlocal.md); these kernels compute the same Nyström
rule on the m-point grid s_i = 2πi/m, for the nonlocal model's right-hand side:

    K[f](s_i) = Σ_j W_ij [f_j + e_ij (e_ij · f_j)],
    W_ij = Q_ij ρ_ij,  ρ_ij = 2|sin((s_j − s_i)/2)| / |x_i − x_j|  (ρ_ii = 1/|x'_i|),
    Q_ij = q_{(j−i) mod m} + 2 log(4/π) δ_ij,
    e_ij = (x_i − x_j)/|x_i − x_j|  (e_ii = x'_i/|x'_i|),

with q the product-integration weights of ``nonlocal_operator.singular_weights``.
Units and conventions: those of ``nonlocal_operator`` (loop length 2π, f the force
density on the fluid, grid values component-major (3, m)).
"""
import numpy as np

from ..jit import kernel
from .nonlocal_operator import LOG_4_OVER_PI


@kernel
def kernel_geometry(position, tangent, singular, weight, direction):
    """The shape's part of the rule: weight (m, m) = W and direction (3, m, m) = e from
    the grid values of x and x' (3, m) and the weights q (m,) (module doc).

    Each pair i < j is measured once (|x_i − x_j| and e_ji = −e_ij), the chords
    2|sin(πk/m)| once per offset k.
    """
    m = position.shape[1]
    chord = np.empty(m)
    for k in range(m):
        chord[k] = 2.0 * abs(np.sin(np.pi * k / m))
    for i in range(m):
        speed = np.sqrt(tangent[0, i] ** 2 + tangent[1, i] ** 2 + tangent[2, i] ** 2)
        weight[i, i] = (singular[0] + 2.0 * LOG_4_OVER_PI) / speed
        for a in range(3):
            direction[a, i, i] = tangent[a, i] / speed
        for j in range(i + 1, m):
            d0 = position[0, i] - position[0, j]
            d1 = position[1, i] - position[1, j]
            d2 = position[2, i] - position[2, j]
            distance = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            forward = j - i
            backward = m - forward  # (i - j) mod m
            weight[i, j] = singular[forward] * chord[forward] / distance
            weight[j, i] = singular[backward] * chord[backward] / distance
            e0 = d0 / distance
            e1 = d1 / distance
            e2 = d2 / distance
            direction[0, i, j] = e0
            direction[1, i, j] = e1
            direction[2, i, j] = e2
            direction[0, j, i] = -e0
            direction[1, j, i] = -e1
            direction[2, j, i] = -e2


@kernel
def apply_kernel(weight, direction, f, out):
    """out (3, m) = K[f] on the grid: out_i = Σ_j W_ij [f_j + e_ij (e_ij · f_j)] for grid
    values f (3, m) (``kernel_geometry``'s W and e)."""
    m = f.shape[1]
    for i in range(m):
        acc0 = 0.0
        acc1 = 0.0
        acc2 = 0.0
        for j in range(m):
            e0 = direction[0, i, j]
            e1 = direction[1, i, j]
            e2 = direction[2, i, j]
            f0 = f[0, j]
            f1 = f[1, j]
            f2 = f[2, j]
            w = weight[i, j]
            along = w * (e0 * f0 + e1 * f1 + e2 * f2)
            acc0 += w * f0 + along * e0
            acc1 += w * f1 + along * e1
            acc2 += w * f2 + along * e2
        out[0, i] = acc0
        out[1, i] = acc1
        out[2, i] = acc2
