"""Nonlocal slender-body theory on a closed loop: the plain-NumPy reference operator.

Units are loopsim's: loop length 2π, arc length s ∈ [0, 2π), x (3, 2n+1) a real
truncated Fourier series (``spectral`` layout), f the force density the filament
exerts on the fluid (f = -x'''' + (T x')' - g0 e_z in the loop model).  The
velocity is

    u = (1/c) { Λ[f] + K[f] },   Λ[f] = [(c+1) I + (c-3) x'x'] · f,   c = -2 log ε,

    K[f](s) = ∫_{-π}^{π} [ (I + R̂R̂)/|R| · f(s+σ) - (I + x'x')/|σ| · f(s) ] dσ,
    R = x(s) - x(s+σ),

the paper's §3 SBT with f_h = -f, divided by c so that u → (I + x'x') f (loopsim's
local model) as c → ∞ with K dropped.  The one change from the paper's printed
∫_0^L ... /|s - s'| ds' is the closed-loop form: s' runs over the period centred on s
and |σ| is the arc distance (the printed form depends on where s = 0 is).

**ε in loopsim's units.**  ε = a / L: the filament's cross-section radius a over the
loop's length L.  With L = 2π the radius is a = 2π ε, and a ring (radius R = 1) has
a / R = 2π ε.  The velocity unit is c f / (8 π μ) (f a force per unit length), the
same c as in Λ: the local model's time scale, now at a definite ε.

**Numerics.**  With W(σ) = 1 / (2|sin(σ/2)|) (one over the chord of the unit circle)
and A(s, σ) = 2|sin(σ/2)| (I + R̂R̂)/|R| · f(s+σ), smooth and 2π-periodic in σ for a
smooth non-self-intersecting loop (A(s, 0) = (I + t̂t̂) f(s) / |x'|),

    K[f](s) = ∫ W(σ) [A(s, σ) - A(s, 0)] dσ + 2 log(4/π) A(s, 0),

since ∫_{-π}^{π} (W - 1/|σ|) dσ = 2 log(4/π).  The first integral is done by
product integration: A's trigonometric interpolant on the M-point grid σ_j = 2πj/M
integrated exactly against W, with ∫ W (cos kσ - 1) dσ = -4 h_k,
h_k = Σ_{j=1..k} 1/(2j-1) (:func:`singular_weights`).  With the σ grid equal to the
s grid this is a Nyström rule on grid values, spectrally accurate in M.

**High modes.**  Λ + K is not positive for short waves: on the ring, mode k has a
non-positive eigenvalue from k ≈ 0.68 R/a = 0.108/ε (the coupled tangential-normal
block; the binormal one from k ≈ 1.85 R/a), the known breakdown of SBT at wavelengths
below about nine radii.  A truncation n must stay below it (ε = 1e-2: n ≤ 10; 1e-3: n ≤ 108).

Shapes must be parametrised by arc length (|x'| = 1: the SBT's s is arc length);
:func:`arclength_parametrised` makes such coefficients from any smooth loop.
Derivations and the rigid-ring checks against Johnson & Wu (1979): docs/nonlocal.md;
the closed forms on the circle: ``nonlocal_circle``.
"""
import math

import numpy as np

from .. import spectral

#: ∫_{-π}^{π} [1/(2|sin(σ/2)|) - 1/|σ|] dσ: the chord-versus-arc local constant.
LOG_4_OVER_PI = math.log(4.0 / math.pi)
#: Largest allowed max | |x'| - 1 | by default (the SBT needs an arc-length parametrisation).
ARCLENGTH_TOL = 1e-3
#: Smallest default number of quadrature points.
MIN_QUADRATURE_POINTS = 64


# ---- constants -------------------------------------------------------------------------

def slenderness_constant(eps):
    """c = -2 log ε, with ε = a / L (cross-section radius over loop length; a = 2π ε in
    loopsim's units, where L = 2π)."""
    eps = float(eps)
    if not 0.0 < eps < 1.0:
        raise ValueError(f"eps = a/L must lie in (0, 1), got {eps}")
    return -2.0 * math.log(eps)


def odd_harmonic(k):
    """h_k = Σ_{j=1..k} 1/(2j-1) for integer k ≥ 0 (array-valued, by cumulative sum)."""
    k = np.asarray(k, dtype=int)
    top = int(k.max(initial=0))
    h = np.concatenate(([0.0], np.cumsum(1.0 / (2.0 * np.arange(1, top + 1) - 1.0))))
    return h[k]


def singular_weights(m):
    """Weights q (m,) with Σ_j q_j A(σ_j) = ∫_{-π}^{π} [A(σ) - A(0)] / (2|sin(σ/2)|) dσ
    for A the trigonometric interpolant of its values on σ_j = 2πj/m (exact for
    trigonometric polynomials of degree < m/2; Σ_j q_j = 0)."""
    if m < 3:
        raise ValueError(f"need at least 3 quadrature points, got {m}")
    sigma = spectral.grid(m)
    k = np.arange(1, (m - 1) // 2 + 1)
    q = -(8.0 / m) * (np.cos(np.outer(sigma, k)) @ odd_harmonic(k))
    if m % 2 == 0:  # the Nyquist mode cos(mσ/2) carries weight 1/m, not 2/m
        q -= (4.0 / m) * odd_harmonic(m // 2) * np.cos(np.pi * np.arange(m))
    return q


def default_quadrature_points(*orders):
    """Default M for shapes/forces of the given orders: max(64, 8 * largest order)."""
    return max(MIN_QUADRATURE_POINTS, 8 * max(orders))


# ---- input handling ---------------------------------------------------------------------

def _shape(x):
    x = np.asarray(x, dtype=float)
    if x.ndim != 2 or x.shape[0] != 3:
        raise ValueError(f"x must be coefficients of shape (3, 2n+1), got {x.shape}")
    return x, spectral.order_of(x.shape[1])


def _grid_size(x_order, f, f_on_grid, quadrature_points):
    """Number of grid points M from the inputs (f on the grid fixes it)."""
    if f_on_grid:
        m = np.shape(f)[-1]
        if quadrature_points is not None and quadrature_points != m:
            raise ValueError(f"f has {m} grid values but quadrature_points = {quadrature_points}")
    elif quadrature_points is None:
        f_order = 0 if f is None else spectral.order_of(np.shape(f)[-1])
        m = default_quadrature_points(x_order, f_order)
    else:
        m = int(quadrature_points)
    if m < 2 * x_order + 1:
        raise ValueError(f"{m} quadrature points cannot resolve a shape of order {x_order}")
    return m


def _force_grid(f, m, f_on_grid):
    """Grid values (3, m) of the force, given as coefficients or (f_on_grid) grid values."""
    f = np.asarray(f, dtype=float)
    if f.ndim != 2 or f.shape[0] != 3:
        raise ValueError(f"f must have shape (3, 2n+1) or (3, M), got {f.shape}")
    if f_on_grid:
        return f
    n_f = spectral.order_of(f.shape[1])
    if m < 2 * n_f + 1:
        raise ValueError(f"{m} quadrature points cannot resolve a force of order {n_f}")
    return f @ spectral.synthesis_matrix(n_f, m).T


def _output(u, order):
    """Grid values (order None) or their projection onto order ``order``."""
    if order is None:
        return u
    return u @ spectral.analysis_matrix(order, u.shape[-1]).T


def arclength_error(x, points=None):
    """max over s of | |x'(s)| - 1 | on a fine grid (0 for an arc-length parametrisation)."""
    x, n = _shape(x)
    m = points or max(MIN_QUADRATURE_POINTS, 8 * n + 1)
    speed = np.linalg.norm(x @ spectral.synthesis_matrix(n, m, 1).T, axis=0)
    return float(np.max(np.abs(speed - 1.0)))


# ---- the shape's kernel on the grid -------------------------------------------------------

def kernel_geometry(x, m, arclength_tol=ARCLENGTH_TOL):
    """The shape's part of the Nyström rule on the m-point grid s_i = 2πi/m.

    Returns (tangent, weight, direction): x'(s_i) (3, m); the (m, m) matrix
    Q_ij ρ_ij with ρ_ij = 2|sin((s_j - s_i)/2)| / |x_i - x_j| (ρ_ii = 1/|x'_i|) and
    Q_ij = q_{(j-i) mod m} + 2 log(4/π) δ_ij (:func:`singular_weights`); and the unit
    vectors e_ij = (x_i - x_j)/|x_i - x_j| (3, m, m), e_ii = x'_i/|x'_i|.  Then
    K[f] at s_i is Σ_j (Qρ)_ij [f_j + e_ij (e_ij · f_j)].
    """
    x, n = _shape(x)
    if m < 2 * n + 1:
        raise ValueError(f"{m} quadrature points cannot resolve a shape of order {n}")
    position = x @ spectral.synthesis_matrix(n, m).T
    tangent = x @ spectral.synthesis_matrix(n, m, 1).T
    speed = np.linalg.norm(tangent, axis=0)
    if arclength_tol is not None and np.max(np.abs(speed - 1.0)) > arclength_tol:
        raise ValueError(
            f"x is not parametrised by arc length: max | |x'| - 1 | = "
            f"{np.max(np.abs(speed - 1.0)):.3g} > {arclength_tol} (see arclength_parametrised)")
    separation = position[:, :, None] - position[:, None, :]  # R_ij = x_i - x_j
    distance = np.linalg.norm(separation, axis=0)
    offset = (np.arange(m)[None, :] - np.arange(m)[:, None]) % m  # j - i mod m
    chord = 2.0 * np.abs(np.sin(np.pi * offset / m))
    diagonal = np.arange(m)
    distance[diagonal, diagonal] = 1.0
    direction = separation / distance
    direction[:, diagonal, diagonal] = tangent / speed
    rho = chord / distance
    rho[diagonal, diagonal] = 1.0 / speed
    weight = singular_weights(m)[offset]
    weight[diagonal, diagonal] += 2.0 * LOG_4_OVER_PI
    return tangent, weight * rho, direction


def _apply_k(weight, direction, f):
    """Σ_j W_ij [f_j + e_ij (e_ij · f_j)] for grid values f (3, m)."""
    along = np.einsum("aij,aj->ij", direction, f)
    return f @ weight.T + np.einsum("aij,ij->ai", direction, weight * along)


# ---- the operator's pieces, applied --------------------------------------------------------

def K_operator(x, f, quadrature_points=None, *, f_on_grid=False, order=None,
               arclength_tol=ARCLENGTH_TOL):
    """K[f] (module doc): grid values (3, M) on spectral.grid(M), or coefficients of
    order ``order``.  f: coefficients (3, 2n_f+1), or grid values (3, M) if f_on_grid."""
    x, n = _shape(x)
    m = _grid_size(n, f, f_on_grid, quadrature_points)
    _, weight, direction = kernel_geometry(x, m, arclength_tol)
    return _output(_apply_k(weight, direction, _force_grid(f, m, f_on_grid)), order)


def nonlocal_velocity(x, f, eps, quadrature_points=None, *, f_on_grid=False, order=None,
                      arclength_tol=ARCLENGTH_TOL):
    """u = (1/c) { Λ[f] + K[f] } (module doc), c = -2 log ε, ε = a/L.

    f: the force density on the fluid, coefficients (3, 2n_f+1) or, with f_on_grid,
    grid values (3, M).  M = quadrature_points (default
    :func:`default_quadrature_points`).  Returns u on spectral.grid(M) (3, M), or its
    projection onto order ``order`` (3, 2 order + 1).
    """
    x, n = _shape(x)
    c = slenderness_constant(eps)
    m = _grid_size(n, f, f_on_grid, quadrature_points)
    fg = _force_grid(f, m, f_on_grid)
    t, weight, direction = kernel_geometry(x, m, arclength_tol)
    u = (c + 1.0) * fg + (c - 3.0) * t * np.sum(t * fg, axis=0) + _apply_k(weight, direction, fg)
    return _output(u / c, order)


def local_velocity(x, f, quadrature_points=None, *, f_on_grid=False, order=None):
    """The c → ∞, K → 0 limit: u = (I + x'x') · f, loopsim's local model."""
    x, n = _shape(x)
    m = _grid_size(n, f, f_on_grid, quadrature_points)
    fg = _force_grid(f, m, f_on_grid)
    t = x @ spectral.synthesis_matrix(n, m, 1).T
    return _output(fg + t * np.sum(t * fg, axis=0), order)


# ---- the operator as a matrix ----------------------------------------------------------------

def K_grid_matrix(x, m, arclength_tol=ARCLENGTH_TOL):
    """The Nyström matrix of K on grid values: (3m, 3m), index a*m + i for component a
    at s_i (i.e. ``f.reshape(-1)`` of an (3, m) array)."""
    _, weight, direction = kernel_geometry(x, m, arclength_tol)
    block = np.einsum("aij,bij->aibj", direction, direction) * weight[None, :, None, :]
    for a in range(3):
        block[a, :, a, :] += weight
    return block.reshape(3 * m, 3 * m)


def _coefficient_matrix(grid_matrix, n, m):
    """P_n G S_n on flattened coefficients (3(2n+1), 3(2n+1)), index a*(2n+1) + j."""
    synthesis = spectral.synthesis_matrix(n, m)
    analysis = spectral.analysis_matrix(n, m)
    g = grid_matrix.reshape(3, m, 3, m)
    out = np.einsum("ki,aibj,jl->akbl", analysis, g, synthesis, optimize=True)
    size = 3 * spectral.n_coeffs(n)
    return out.reshape(size, size)


def _tangent_block(x, m):
    x, n = _shape(x)
    t = x @ spectral.synthesis_matrix(n, m, 1).T
    tt = np.zeros((3, m, 3, m))
    diagonal = np.arange(m)
    tt[:, diagonal, :, diagonal] = np.einsum("ai,bi->iab", t, t)
    return tt.reshape(3 * m, 3 * m)


def nonlocal_matrix(x, eps, n=None, quadrature_points=None, arclength_tol=ARCLENGTH_TOL):
    """The map from the force's coefficients to u's, P_n (1/c)(Λ + K) on order n
    (default: the shape's order): (3K, 3K) with K = 2n+1, acting on ``f.reshape(-1)``
    of a (3, K) array (component-major) and returning u's coefficients the same way."""
    x, nx = _shape(x)
    n = nx if n is None else n
    m = default_quadrature_points(nx, n) if quadrature_points is None else quadrature_points
    c = slenderness_constant(eps)
    grid = (c + 1.0) * np.eye(3 * m) + (c - 3.0) * _tangent_block(x, m)
    grid += K_grid_matrix(x, m, arclength_tol)
    return _coefficient_matrix(grid / c, n, m)


def local_matrix(x, n=None, quadrature_points=None):
    """:func:`nonlocal_matrix` of the local model u = (I + x'x') f."""
    x, nx = _shape(x)
    n = nx if n is None else n
    m = default_quadrature_points(nx, n) if quadrature_points is None else quadrature_points
    return _coefficient_matrix(np.eye(3 * m) + _tangent_block(x, m), n, m)


# ---- the elastic loop: tension and velocity --------------------------------------------------

def loop_tension_and_velocity(x, g0, w, mobility):
    """The loop model's tension T and velocity u (both order n) for the shape x (3, 2n+1),
    with u = ``mobility`` applied to the force (a (3K, 3K) coefficient map, K = 2n+1:
    :func:`nonlocal_matrix` or :func:`local_matrix`):

        f = P_n[ -x'''' + (T x')' - g0 e_z ],   u = mobility f,
        T = argmin ∫ ε² ds,   ε = x'·u' - w (1 - x'·x'),

    ε on the 4n + 1-point grid (order 2n: its grid sum is the exact L² norm), the least
    squares dense (``numpy.linalg.lstsq`` on the K tension basis functions): the reference
    the nonlocal model's compiled tension solve is to be tested against.  With
    :func:`local_matrix` it is loopsim's local model.  Returns (T (K,), u (3, K)).
    """
    x, n = _shape(x)
    k = spectral.n_coeffs(n)
    m = 4 * n + 1
    d = spectral.derivative_matrix(n)
    synthesis = spectral.synthesis_matrix(n, m)
    tangent = (x @ d.T) @ synthesis.T
    bending = -(x @ np.linalg.matrix_power(d, 4).T)
    bending[2, 0] -= g0

    def length_rate(tension):
        """(x'·u' on the grid, u) for the tension coefficients ``tension``."""
        flux = spectral.resize(spectral.fit((tension @ synthesis.T) * tangent), n)
        u = (mobility @ (bending + flux @ d.T).reshape(-1)).reshape(3, k)
        return np.sum(tangent * ((u @ d.T) @ synthesis.T), axis=0), u

    stretch = w * (1.0 - np.sum(tangent * tangent, axis=0))
    affine = length_rate(np.zeros(k))[0] - stretch
    columns = np.array([length_rate(np.eye(k)[j])[0] - stretch - affine for j in range(k)]).T
    tension = np.linalg.lstsq(columns, -affine, rcond=None)[0]
    return tension, length_rate(tension)[1]


def nonlocal_loop_velocity(x, g0, w, eps, quadrature_points=None,
                           arclength_tol=ARCLENGTH_TOL):
    """(T, u) of the loop in nonlocal slender-body theory at slenderness ε
    (:func:`loop_tension_and_velocity` with :func:`nonlocal_matrix`)."""
    return loop_tension_and_velocity(
        x, g0, w, nonlocal_matrix(x, eps, quadrature_points=quadrature_points,
                                  arclength_tol=arclength_tol))


# ---- rigid loops ---------------------------------------------------------------------------

def _rigid_order(x_order, n):
    """Default order of a rigid motion's force density: it is not band-limited like the
    shape (on the circle the edgewise one has Cartesian order 2), so max(8, 2 n_x)."""
    return max(8, 2 * x_order) if n is None else n


def _rigid_system(x, eps, n, quadrature_points, arclength_tol):
    """The coefficient matrix of u[f] on order n and the arm x - x̄ (order n)."""
    x, nx = _shape(x)
    n = _rigid_order(nx, n)
    if eps is None:
        a = local_matrix(x, n, quadrature_points)
    else:
        a = nonlocal_matrix(x, eps, n, quadrature_points, arclength_tol)
    arm = spectral.resize(x, n)
    arm[:, 0] = 0.0  # x - x̄
    return a, arm


def rigid_force(x, velocity, angular_velocity=(0.0, 0.0, 0.0), eps=None, n=None,
                quadrature_points=None, arclength_tol=ARCLENGTH_TOL):
    """Coefficients (3, 2n+1) of the force density f with u[f] = U + Ω × (x - x̄) (x̄ the
    mean of x over s), solved on order n (default max(8, 2 n_x)).  eps=None: the local
    model u = (I + x'x') f; otherwise the nonlocal one."""
    a, arm = _rigid_system(x, eps, n, quadrature_points, arclength_tol)
    rhs = np.cross(np.asarray(angular_velocity, dtype=float), arm, axis=0)
    rhs[:, 0] += np.asarray(velocity, dtype=float)
    return np.linalg.solve(a, rhs.reshape(-1)).reshape(rhs.shape)


def force_and_torque(x, f):
    """Total force ∫ f ds and torque ∫ (x - x̄) × f ds about the centroid (arc length s)."""
    x, nx = _shape(x)
    nf = spectral.order_of(np.shape(f)[-1])
    m = 2 * (nx + nf) + 1  # the products' order is nx + nf: their means are exact here
    arm = x @ spectral.synthesis_matrix(nx, m).T - x[:, :1]
    fg = np.asarray(f, dtype=float) @ spectral.synthesis_matrix(nf, m).T
    return (2.0 * np.pi * np.mean(fg, axis=1),
            2.0 * np.pi * np.mean(np.cross(arm, fg, axis=0), axis=1))


def rigid_resistance(x, eps=None, n=None, quadrature_points=None, arclength_tol=ARCLENGTH_TOL):
    """6x6 resistance matrix of the loop held rigid: [F; T] = R [U; Ω], columns the unit
    translations then rotations about the centroid (:func:`rigid_force`,
    :func:`force_and_torque`).  eps=None: the local model."""
    a, arm = _rigid_system(x, eps, n, quadrature_points, arclength_tol)
    rhs = np.zeros((6,) + arm.shape)
    for j in range(3):
        rhs[j, j, 0] = 1.0
        rhs[3 + j] = np.cross(np.eye(3)[j], arm, axis=0)
    forces = np.linalg.solve(a, rhs.reshape(6, -1).T).T.reshape(rhs.shape)
    return np.stack([np.concatenate(force_and_torque(x, f)) for f in forces], axis=1)


def rigid_velocity(x, force, torque=(0.0, 0.0, 0.0), eps=None, n=None, quadrature_points=None,
                   arclength_tol=ARCLENGTH_TOL):
    """(U, Ω) of the rigid loop under total force ``force`` and torque ``torque`` about
    its centroid (a uniform density g has force 2π g and no torque)."""
    r = rigid_resistance(x, eps, n, quadrature_points, arclength_tol)
    motion = np.linalg.solve(r, np.concatenate((np.asarray(force, float),
                                                np.asarray(torque, float))))
    return motion[:3], motion[3:]


# ---- shapes ---------------------------------------------------------------------------------

def arclength_parametrised(x, n, points=None):
    """Order-n coefficients of the closed curve x (any smooth parametrisation) parametrised
    by arc length from x(0), scaled about the origin to length 2π."""
    x, nx = _shape(x)
    p = points or 2 * max(256, 4 * (max(nx, n) + 1)) + 1
    speed = spectral.fit(np.linalg.norm(x @ spectral.synthesis_matrix(nx, p, 1).T, axis=0))
    order = spectral.order_of(speed.size)
    k = np.arange(1, order + 1)
    a, b = speed[1:order + 1] / k, speed[order + 1:] / k
    target = spectral.grid(p) * speed[0]  # arc length 2πj/p of the length 2π speed[0]
    alpha = spectral.grid(p)
    for _ in range(50):
        arc = speed[0] * alpha + np.sin(np.outer(alpha, k)) @ a \
            + (1.0 - np.cos(np.outer(alpha, k))) @ b
        step = (arc - target) / spectral.evaluate(speed, alpha)
        alpha = alpha - step
        if np.max(np.abs(step)) < 1e-14:  # Newton: quadratic, ~5 steps
            break
    fine = spectral.fit(spectral.evaluate(x, alpha))
    return spectral.resize(fine, n) / speed[0]
