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
from .loop_jacobian import mobility_jacobian
from .loop_maps import force_map, length_creation_map, shape_on_grid, velocity_from_blocks
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


@kernel
def nonlocal_velocity_map(c, weight, direction, ws):
    """Map (2) of ``loop_maps`` in nonlocal hydrodynamics, for every column of ws.force
    (M, 3, J) (``loop_maps.force_map``): ws.mobile = (1/c) [(c+1) f + (c−3) (x'·f) x' + K[f]]
    on the grid, K from :func:`kernel_geometry`'s weight and direction on the same grid."""
    t, f, mobile = ws.tangent, ws.force, ws.mobile
    m, cols = f.shape[0], f.shape[2]
    inverse_c = 1.0 / c
    for i in range(m):
        for col in range(cols):
            h = t[0, i] * f[i, 0, col] + t[1, i] * f[i, 1, col] + t[2, i] * f[i, 2, col]
            for a in range(3):
                mobile[i, a, col] = (c + 1.0) * f[i, a, col] + (c - 3.0) * h * t[a, i]
        for j in range(m):
            w = weight[i, j]
            e0 = direction[0, i, j]
            e1 = direction[1, i, j]
            e2 = direction[2, i, j]
            for col in range(cols):
                f0 = f[j, 0, col]
                f1 = f[j, 1, col]
                f2 = f[j, 2, col]
                along = w * (e0 * f0 + e1 * f1 + e2 * f2)
                mobile[i, 0, col] += w * f0 + along * e0
                mobile[i, 1, col] += w * f1 + along * e1
                mobile[i, 2, col] += w * f2 + along * e2
        for col in range(cols):
            for a in range(3):
                mobile[i, a, col] *= inverse_c


@kernel
def nonlocal_loop_velocity(x, g0, w, c, singular, ops, ws, position, weight, direction, u_out):
    """Velocity coefficients u (3, K) of the loop x (3, K) in nonlocal slender-body theory
    (c = −2 log ε), its least-squares tension left in ws.tension: ``loop_maps``' column
    blocks with map (2) replaced by :func:`nonlocal_velocity_map`, all on the local model's
    M = 4n + 1 grid (``ops``, ``ws`` of ``loop_maps``; singular = the weights q of that
    grid; position (3, M), weight (M, M) and direction (3, M, M) scratch).  The plain-NumPy
    twin: ``nonlocal_operator.loop_tension_and_velocity`` with ``nonlocal_matrix`` on M
    points."""
    shape_on_grid(x, ops, ws)
    np.dot(x, ops.S0T, position)
    kernel_geometry(position, ws.tangent, singular, weight, direction)
    force_map(g0, ops, ws)
    nonlocal_velocity_map(c, weight, direction, ws)
    length_creation_map(w, ops, ws)
    velocity_from_blocks(ops, ws, u_out)


@kernel
def nonlocal_jacobian(x, g0, w, c, singular, ops, ws, position, weight, direction, jac):
    """Exact Jacobian J = ∂u/∂x (3K × 3K, component-major) of :func:`nonlocal_loop_velocity`:
    the chain rule of ``loop_jacobian.mobility_jacobian`` for the mobility
    m[f] = (1/c)[(c+1) f + (c−3)(x'·f) x' + K[f]], the rule's change with the shape (W and
    e through the grid positions and x') included."""
    u = np.empty_like(x)
    nonlocal_loop_velocity(x, g0, w, c, singular, ops, ws, position, weight, direction, u)
    mobility_jacobian(w, (c + 1.0) / c, (c - 3.0) / c, 1.0 / c, weight, direction, position,
                      ops, ws, jac)
