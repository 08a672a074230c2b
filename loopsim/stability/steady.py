"""Steady in-plane shapes (relative equilibria): their equations, Jacobian and Newton solve.

Their continuation in q and their stability are in ``stability.branch``.

The state is x (3, K), K = 2n + 1, and dx/dt = F(x; g0) is loopsim's spectral
right-hand side (``models.local_sbt.loop_velocity``, tension solve included).

Frame.  Every in-plane problem is posed at θ0 = 90°: the loop lies in the
vertical x–z plane, x = X(s) e_x + Z(s) e_z, gravity -g0 e_z lies in the plane
and q = g0 / 3.  Nothing is lost: for a loop in a plane tilted by θ, only the
in-plane gravity component g0 sin θ = 3q shapes it (the normal component adds
the uniform velocity -g0 cos θ e_n and nothing else, because t·e_n = 0), and
both stability sectors depend on q alone (docs/stability.md §1; checked for
the branch in the tests by tilting a steady shape).

Steady shapes.  A relative equilibrium translates rigidly, possibly with its
material points sliding along the curve: x(s, t) = x*(s + c t) + V t, so

    F(x*; 3q) = V + c x*'                                               (1)

(V uniform, c the sliding rate; the arc-length shift s → s + σ is a symmetry
of the equations).  Unknowns u = [X (K), Z (K), V_x, V_z, c], equations
H(u; q) = 0 (2K + 3 rows):

    F_x(x) - V_x e_0 - c D X = 0,   F_z(x) - V_z e_0 - c D Z = 0      (2K rows: (1))
    X_0 = 0,   Z_0 = 0                                               (translations)
    ⟨x_ref', x - x_ref⟩ = 0                                           (arc-length shift)

with e_0 the mean coefficient, D = ``spectral.derivative_matrix``, ⟨·,·⟩ the
L² product of the coefficient layout (``full_linear.l2_weights``) and x_ref the
previous point of the branch.  The rigid motions left by gravity along -z are
exactly these: the translations and the shift; an in-plane rotation changes
the angle to gravity (no phase condition), and the two rotations out of the
plane leave it (they are neutral out-of-plane modes, below).  ∂H/∂u is built
from the exact Jacobian ``loop_jacobian``; F is affine in g0 at fixed shape
(the tension solve is linear in the affine part), so ∂F/∂q = 3 [F(x; 1) -
F(x; 0)] exactly.  The steady shapes do not depend on the length penalty w:
with c = 0 and V uniform, (1) makes ε = -w (1 - |x'|²) the least-squares
residual, orthogonal to the tension's range, so w changes neither T nor F.
Their length error is what the order-n tension cannot remove (``length_error``).
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from .. import diagnostics, models, spectral
from ..defaults import DEFAULT_W
from ..models import local_sbt
from .full_linear import l2_weights

__all__ = [
    "PLANE", "NORMAL", "planar_state", "steady_velocity", "velocity_jacobian", "plane_index",
    "steady_residual", "steady_jacobian", "SteadyShape", "steady_shape",
    "mirror_symmetric_index", "newton", "solve_steady", "tilt_shape", "to_plane",
]

#: Components of x in the loop's plane (e_x, e_z) and normal to it (e_y), at θ0 = 90°.
PLANE = (0, 2)
NORMAL = 1
#: Newton: converged when max|H| ≤ NEWTON_TOL · max(1, max|F|); at most NEWTON_MAX_ITER.
NEWTON_TOL = 1e-12
NEWTON_MAX_ITER = 12


# ---------------------------------------------------------------- the steady equations
def planar_state(n, x_plane):
    """x (3, K) from the in-plane coefficients [X, Z] (2, K) (Y = 0)."""
    x = np.zeros((3, spectral.n_coeffs(n)))
    x[PLANE[0]], x[PLANE[1]] = x_plane
    return x


def steady_velocity(x, g0, w, problem):
    """u = F(x) (3, K) at gravity g0 and penalty w, on ``problem``'s operators."""
    x = np.ascontiguousarray(x, dtype=float)
    u = np.empty_like(x)
    models.evaluate(problem._replace(g0=float(g0), w=float(w)), x.reshape(-1), u.reshape(-1),
                    np.empty(x.shape[1]))
    return u


def steady_residual(x, velocity, slide, q, w=DEFAULT_W):
    """R = F(x; 3q) - V e_0 - c D x  (3, K): zero for a relative equilibrium, eq. (1)."""
    x = np.ascontiguousarray(x, dtype=float)
    n = spectral.order_of(x.shape[1])
    problem = local_sbt.make_problem(n, 3.0 * q, w)
    r = steady_velocity(x, 3.0 * q, w, problem) - slide * x @ spectral.derivative_matrix(n).T
    r[:, 0] -= velocity
    return r


def velocity_jacobian(x, g0, w, problem):
    """∂F/∂x (3K, 3K, component-major) at x, as :func:`steady_velocity`."""
    x = np.ascontiguousarray(x, dtype=float)
    jac = np.empty((x.size, x.size))
    models.evaluate_jacobian(problem._replace(g0=float(g0), w=float(w)), x.reshape(-1), jac)
    return jac


def plane_index(k):
    """Indices of X and Z in x.ravel() (component-major)."""
    return np.concatenate([np.arange(c * k, (c + 1) * k) for c in PLANE])


def steady_jacobian(x, slide, q, w=DEFAULT_W, x_ref=None):
    """H(u; q) of the module docstring, ∂H/∂u (2K+3, 2K+3) and ∂H/∂q (2K+3) at a planar x.

    u = [X, Z, V_x, V_z, c]; V is taken as the mean of F (so the mean rows of H
    vanish and H is the residual of (1) for that V).  Returns (H, dH/du, dH/dq, F).
    """
    x = np.ascontiguousarray(x, dtype=float)
    k = x.shape[1]
    n = spectral.order_of(k)
    d = spectral.derivative_matrix(n)
    x_ref = x if x_ref is None else x_ref
    wts = np.tile(l2_weights(n), 2)
    problem = local_sbt.make_problem(n, 3.0 * q, w)
    f = steady_velocity(x, 3.0 * q, w, problem)
    jac = velocity_jacobian(x, 3.0 * q, w, problem)
    idx = plane_index(k)
    jp = jac[np.ix_(idx, idx)]
    xp = x[list(PLANE)]
    dxp = xp @ d.T
    size = 2 * k + 3
    h = np.zeros(size)
    dh = np.zeros((size, size))
    r = f[list(PLANE)] - slide * dxp
    r[:, 0] = 0.0                         # V = mean of F
    h[:2 * k] = r.ravel()
    dh[:2 * k, :2 * k] = jp - slide * np.kron(np.eye(2), d)
    dh[0, 2 * k] = dh[k, 2 * k + 1] = -1.0
    dh[:2 * k, 2 * k + 2] = -dxp.ravel()
    h[2 * k], h[2 * k + 1] = xp[0, 0], xp[1, 0]
    dh[2 * k, 0] = dh[2 * k + 1, k] = 1.0
    tangent_ref = (x_ref[list(PLANE)] @ d.T).ravel() * wts
    h[2 * k + 2] = tangent_ref @ (xp - x_ref[list(PLANE)]).ravel()
    dh[2 * k + 2, :2 * k] = tangent_ref
    f1 = steady_velocity(x, 1.0, w, problem)
    f0 = steady_velocity(x, 0.0, w, problem)
    dq = np.zeros(size)
    dq[:2 * k] = 3.0 * (f1 - f0)[list(PLANE)].ravel()
    for c in range(2):
        dq[c * k] = 0.0                   # the mean rows hold V, which absorbs it
    return h, dh, dq, f


@dataclasses.dataclass
class SteadyShape:
    """A relative equilibrium at q: x (3, K) (Y = 0), velocity V (3), sliding rate c,
    multiplier T (K), and the Newton residual max|F - V - c x'| / max(1, max|F|)."""

    q: float
    x: np.ndarray
    velocity: np.ndarray
    slide: float
    multiplier: np.ndarray
    residual: float
    iterations: int
    w: float = DEFAULT_W

    @property
    def n(self):
        return spectral.order_of(self.x.shape[1])

    @property
    def aspect_ratio(self):
        return diagnostics.aspect_ratio(self.x)

    @property
    def length_error(self):
        return diagnostics.relative_length_error(self.x)


def residual_norm(x, slide, q, w):
    f = steady_residual(x, 0.0, slide, q, w)
    scale = max(1.0, np.abs(f).max())
    f[:, 0] = 0.0
    return float(np.abs(f).max() / scale)


def steady_shape(x, slide, q, w, iterations):
    problem = local_sbt.make_problem(spectral.order_of(x.shape[1]), 3.0 * q, w)
    f = steady_velocity(x, 3.0 * q, w, problem)
    return SteadyShape(q=float(q), x=x, velocity=f[:, 0].copy(), slide=float(slide),
                       multiplier=problem.ws.tension.copy(),
                       residual=residual_norm(x, slide, q, w), iterations=iterations, w=float(w))


def mirror_symmetric_index(n):
    """Unknowns (and rows) of H that stay when x is mirror symmetric about the vertical,
    X(-s) = -X(s), Z(-s) = Z(s): X's sine and Z's cosine coefficients, V_z (and the
    rows: (1)'s X-sine and Z-cosine rows, the phase Z_0 = 0).  F maps this subspace
    into itself (the mirror x → -x, s → -s is a symmetry), V_x = c = 0 on it and the
    shift and X_0 conditions hold identically."""
    k = 2 * n + 1
    return np.concatenate([np.arange(n + 1, k), np.arange(k, k + n + 1), [2 * k + 1]])


def newton(x, slide, q, w, extra=None, x_ref=None, free=None):
    """Newton on H = 0 (q fixed when extra is None) or on [H; g] = 0 with q unknown,
    extra = (a_x (2K), a_q, target): the linear condition ⟨a_x, [X, Z]⟩ + a_q q = target.
    ``free``: the unknowns (= rows) solved for (default all; ``mirror_symmetric_index``).

    Returns (x, slide, q, iterations) or None if it does not converge.
    """
    x = x.copy()
    k = x.shape[1]
    x_ref = x.copy() if x_ref is None else x_ref
    free = np.arange(2 * k + 3) if free is None else free
    for it in range(NEWTON_MAX_ITER + 1):
        h, dh, dq, f = steady_jacobian(x, slide, q, w, x_ref)
        scale = max(1.0, np.abs(f).max())
        g = 0.0
        if extra is not None:
            a_x, a_q, target = extra
            g = a_x @ x[list(PLANE)].ravel() + a_q * q - target
        if max(np.abs(h).max(), abs(g)) <= NEWTON_TOL * scale:
            return x, slide, q, it
        if it == NEWTON_MAX_ITER:
            break
        step = np.zeros(2 * k + 3)
        dq_step = 0.0
        sub = dh[np.ix_(free, free)]
        if extra is None:
            step[free] = np.linalg.solve(sub, -h[free])
        else:
            size = free.size
            big = np.zeros((size + 1, size + 1))
            big[:size, :size] = sub
            big[:size, size] = dq[free]
            ax = np.zeros(2 * k + 3)
            ax[:2 * k] = a_x
            big[size, :size] = ax[free]
            big[size, size] = a_q
            full = np.linalg.solve(big, -np.concatenate([h[free], [g]]))
            step[free], dq_step = full[:size], full[size]
        if not np.all(np.isfinite(step)) or not math.isfinite(dq_step):
            return None
        for i, c in enumerate(PLANE):
            x[c] += step[i * k:(i + 1) * k]
        slide += step[2 * k + 2]
        q += dq_step
    return None


def solve_steady(x_guess, q, w=DEFAULT_W, slide=0.0, symmetric=False):
    """Newton on the steady equations (1) at fixed q from a planar guess x (3, K) (its Y
    row is dropped, its mean removed), with all phase conditions, or within the
    mirror-symmetric subspace (``symmetric``; the guess's antisymmetric part is kept
    as it is).  Raises ValueError if it does not converge."""
    x = np.ascontiguousarray(x_guess, dtype=float).copy()
    n = spectral.order_of(x.shape[1])
    x[NORMAL] = 0.0
    x[:, 0] = 0.0
    free = mirror_symmetric_index(n) if symmetric else None
    out = newton(x, float(slide), float(q), float(w), free=free)
    if out is None:
        raise ValueError(f"Newton on the steady equations did not converge at q = {q}")
    return steady_shape(out[0], out[1], q, w, out[3])



# ---------------------------------------------------------------- other frames
def tilt_shape(x, theta0):
    """A shape of the x–z plane (the θ0 = 90° frame) turned about e_x so that its plane is
    tilted by θ0 (radians): e_z → [0, cos θ0, sin θ0], e_y → [0, sin θ0, -cos θ0].  The
    in-plane gravity is then g0 sin θ0: the same q for g0 = 3q / sin θ0."""
    c, s = math.cos(theta0), math.sin(theta0)
    return np.array([[1.0, 0.0, 0.0], [0.0, s, c], [0.0, -c, s]]) @ x


def to_plane(x):
    """A nearly planar loop (3, K) in any orientation, as [X, Z] in its plane, with its tilt.

    Plane normal ν: the covariance eigenvector of the smallest eigenvalue; in-plane
    horizontal axis a = ν × e_z / |ν × e_z|, in-plane upward axis b = a × ν (b_z ≥ 0).
    Returns (planar x (3, K) with Y = 0 and mean 0, tilt θ in radians, out-of-plane RMS).
    The rotation about the vertical is a symmetry, so a is any horizontal direction.
    """
    _, vectors = diagnostics.principal_axes(x)
    nu = vectors[:, 0]
    a = np.cross(nu, [0.0, 0.0, 1.0])
    a /= np.linalg.norm(a)
    b = np.cross(a, nu)
    if b[2] < 0:
        b, nu = -b, -nu
    xc = x.copy()
    xc[:, 0] = 0.0
    out = np.zeros_like(x)
    out[PLANE[0]] = a @ xc
    out[PLANE[1]] = b @ xc
    theta = math.acos(min(1.0, abs(nu[2])))
    return out, theta, float(diagnostics.rms_amplitude((nu @ xc)[None]))
