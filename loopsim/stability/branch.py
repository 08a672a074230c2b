"""The branch of steady in-plane shapes: its continuation in q from the circle and its
stability (the steady equations and their Newton solve: ``stability.steady``).

Continuation.  In the mirror-symmetric subspace X(-s) = -X(s), Z(-s) = Z(s)
(``mirror_symmetric_index``; invariant under F, and where the runs' terminal
shapes lie), where the bifurcation is simple.  Pseudo-arclength in y = (x, q):
tangent t the null vector of [∂H/∂u, ∂H/∂q] (norm ⟨x, x⟩ + q²), predictor
y + h t, corrector Newton on H = 0 plus ⟨t, y - y_pred⟩ = 0; a corrector that
lands far from the prediction or turns the tangent sharply (e.g. back onto the
circle) is rejected and the step halved.  The branch leaves the translating
circle at the in-plane threshold q_c (``full_linear.critical_q``, 8.9001
converged): the first corrector uses the hyperplane ⟨φ, x - x_circle⟩ = h, φ
the mirror-symmetric null vector of ∂H/∂u at the circle (the critical
eigenspace is double: the mirror-symmetric and the antisymmetric flattening);
q_bifurcation is then measured from the branch itself, from
(q(h) + q(-h)) / 2 at h = ``START_AMPLITUDE`` and 2h (Richardson, O(h⁴)).

Stability.  Perturbations ride with the sliding shape, x = x*(s + ct) + V t +
δ(s + ct, t): dδ/dt = L δ with L = J - c D, J = ∂F/∂x(x*).  At θ0 = 90° the
mirror y → -y splits L exactly into an in-plane block (X, Z) and an
out-of-plane block (Y).  Neutral modes (L maps them into the translations):
in-plane N_in = {e_x, e_z, x*'} (translations, shift); out-of-plane
N_out = {Y = 1, Y = X(s), Y = Z(s)} (translation along e_y, rotation about
e_z = e_z × x*, rotation about e_x = e_x × x*, the latter a shape at another
tilt, the same q to first order).  The spectrum is that of the quotient maps
Qᵀ L Q (Q an orthonormal basis of N^⊥), as for the circle.  In-plane modes
that change the length (|x*'·δ'| on the grid above ``STRETCH_FRACTION`` of
|δ'|) are penalty/truncation artefacts (σ ≈ -2w and beyond; docs/stability.md)
and are left out of the leading in-plane eigenvalue; the rates are computed
with the penalty ``SPECTRUM_W``, which moves the stretch modes far below.

Crossing.  q_loss_out_of_plane is the first q on the in-plane-stable half where
the leading out-of-plane Re σ reaches 0 (brentq on steady shapes solved at
intermediate q).
"""
from __future__ import annotations

import dataclasses
import functools
import math

import numpy as np
from scipy.optimize import brentq

from .. import spectral, validation
from ..defaults import DEFAULT_W
from ..models import local_sbt
from ..shapes import inclined_circle
from .full_linear import critical_q, l2_weights
# The steady equations, re-exported: ``stability.branch`` has always offered them.
from .steady import (  # noqa: F401
    NORMAL, PLANE, SteadyShape, mirror_symmetric_index, newton, planar_state, plane_index,
    solve_steady, steady_jacobian, steady_residual, steady_shape, steady_velocity, tilt_shape,
    to_plane, velocity_jacobian,
)

__all__ = [
    "PLANE", "NORMAL", "steady_residual", "steady_jacobian", "SteadyShape", "solve_steady",
    "planar_state", "tilt_shape", "to_plane", "mirror_symmetric_index",
    "neutral_modes", "stability", "Branch", "continue_branch", "steady_branch",
    "q_loss_out_of_plane", "branch_rows", "branch_summary", "ROW_FIELDS", "upper_half", "steady_branch_to",
    "out_of_plane_loss_near", "rate_crossing",
]

#: First corrector's distance from the circle along φ (L² amplitude), and the
#: pseudo-arclength step limits.
START_AMPLITUDE = 1e-3
STEP_FIRST = 0.02
STEP_MIN = 1e-5
STEP_MAX = 0.1
#: In-plane eigenvectors with RMS |x*'·δ'| above this fraction of RMS |δ'| are stretch modes
#: (measured gap, n = 8, q = 12: physical modes ≤ 0.14, stretch modes ≥ 0.62).
STRETCH_FRACTION = 0.3
#: A sector is stable when its leading Re σ is below -STABILITY_TOL.
STABILITY_TOL = 1e-8
#: Penalty rate used for the spectrum (stretch modes at -2 SPECTRUM_W, out of the way).
SPECTRUM_W = 1000.0


# ---------------------------------------------------------------- stability
def neutral_modes(x):
    """In-plane (3, 3K) and out-of-plane (3, 3K) neutral generators at the planar shape x:
    e_x, e_z, x*' and e_y, e_z × x*, e_x × x* (rows, x.ravel() layout)."""
    k = x.shape[1]
    n = spectral.order_of(k)
    dx = x @ spectral.derivative_matrix(n).T
    one = np.zeros(k)
    one[0] = 1.0
    n_in = np.zeros((3, 3, k))
    n_in[0, PLANE[0]] = one
    n_in[1, PLANE[1]] = one
    n_in[2] = dx
    n_out = np.zeros((3, 3, k))
    n_out[0, NORMAL] = one
    n_out[1] = np.cross(np.array([0.0, 0.0, 1.0])[:, None], x, axis=0)
    n_out[2] = np.cross(np.array([1.0, 0.0, 0.0])[:, None], x, axis=0)
    return n_in.reshape(3, -1), n_out.reshape(3, -1)


def _quotient_basis(columns, neutral):
    """Orthonormal basis of span(columns) ⊖ span(neutral rows); columns orthonormal and
    the neutral vectors inside their span (both in L²-weighted coordinates)."""
    qn, _ = np.linalg.qr(columns.T @ neutral.T)
    u, _, _ = np.linalg.svd(np.eye(columns.shape[1]) - qn @ qn.T)
    return columns @ u[:, : columns.shape[1] - neutral.shape[0]]


def _ordered(values):
    return values[np.lexsort((-values.imag, -values.real))]


def stability(shape, w_spectrum=None):
    """Spectrum of L = J - c D at a steady planar shape, per sector (module docstring).

    J is taken with the penalty ``w_spectrum`` (default max(shape.w, SPECTRUM_W)).
    The steady shape does not depend on w: with c = 0 and V uniform, (1) gives
    ε = -w (1 - |x'|²) = the least-squares residual, orthogonal to the tension's
    range, so changing w changes neither T nor F (checked in the tests).  Physical
    rates do not depend on w either, while the stretch modes sit at -2w; a large
    w moves them out of the way (at w = 10 they cross the in-plane rates near
    q = 14.6 and mix with them).

    Returns a dict: ``in_plane`` (physical eigenvalues, decreasing Re),
    ``stretch`` (the in-plane length-changing ones), ``out_of_plane``,
    ``leading_in_plane``, ``leading_out_of_plane``, ``neutral_leak`` = max|Qᵀ L N| /
    max|L| (0 for exact neutral modes) and the three sector sizes.
    """
    x = np.ascontiguousarray(shape.x)
    k = x.shape[1]
    n = spectral.order_of(k)
    w = max(shape.w, SPECTRUM_W) if w_spectrum is None else float(w_spectrum)
    problem = local_sbt.make_problem(n, 3.0 * shape.q, w)
    op = velocity_jacobian(x, 3.0 * shape.q, w, problem) \
        - shape.slide * np.kron(np.eye(3), spectral.derivative_matrix(n))
    sq = np.sqrt(np.tile(l2_weights(n), 3))
    op_w = sq[:, None] * op / sq[None, :]            # L in L²-orthonormal coordinates
    n_in, n_out = neutral_modes(x)
    eye = np.eye(3 * k)
    q_in = _quotient_basis(eye[:, plane_index(k)], n_in * sq)
    q_out = _quotient_basis(eye[:, NORMAL * k:(NORMAL + 1) * k], n_out * sq)
    nw = np.vstack([n_in, n_out]) * sq
    nw /= np.linalg.norm(nw, axis=1)[:, None]
    leak = float(np.abs(np.hstack([q_in, q_out]).T @ op_w @ nw.T).max() / np.abs(op_w).max())
    lam_in, vec_in = np.linalg.eig(q_in.T @ op_w @ q_in)
    lam_out = np.linalg.eigvals(q_out.T @ op_w @ q_out)
    # stretch test on the grid: RMS of x*'·δ' against RMS |δ'|
    t = x @ problem.ops.S1T
    dv = (((q_in @ vec_in) / sq[:, None]).T.reshape(-1, 3, k)) @ problem.ops.S1T
    frac = np.sqrt(np.sum(np.abs(np.einsum("cm,jcm->jm", t, dv)) ** 2, axis=1)
                   / np.sum(np.abs(dv) ** 2, axis=(1, 2)))
    stretch = frac > STRETCH_FRACTION
    phys, out = _ordered(lam_in[~stretch]), _ordered(lam_out)
    return dict(in_plane=phys, stretch=_ordered(lam_in[stretch]), out_of_plane=out,
                leading_in_plane=complex(phys[0]), leading_out_of_plane=complex(out[0]),
                neutral_leak=leak, sizes=(int(phys.size), int(stretch.sum()), int(out.size)))


# ---------------------------------------------------------------- continuation
@dataclasses.dataclass
class Branch:
    """The branch of mirror-symmetric steady in-plane shapes that leaves the circle at q_c.

    ``q_bifurcation``: q at zero amplitude, measured on the branch: the even part
    (q(h) + q(-h)) / 2 at h = START_AMPLITUDE and 2h off the circle along φ,
    Richardson-extrapolated (error O(h⁴)); ``q_circle``: the circle's in-plane
    threshold (``full_linear.critical_q``); ``shapes``: the steady shapes in arclength order,
    the circle at q_c first, then the side with ⟨φ, x - x_circle⟩ > 0 (``side`` +1) or
    < 0 (-1), as asked; ``null_vector``: φ (2, K) in [X, Z].
    """

    n: int
    w: float
    q_bifurcation: float
    q_circle: float
    null_vector: np.ndarray
    shapes: list
    side: int


def _symmetric_null_vector(n, q, w):
    """φ: the mirror-symmetric critical mode at the circle, as [X, Z] (2, K), unit L² norm,
    signed so that the sin s coefficient of X grows (the loop widens)."""
    k = 2 * n + 1
    x = inclined_circle(n, math.pi / 2)
    _, dh, _, _ = steady_jacobian(x, 0.0, q, w)
    free = mirror_symmetric_index(n)
    _, _, vt = np.linalg.svd(dh[np.ix_(free, free)])
    v = np.zeros(2 * k + 3)
    v[free] = vt[-1]
    phi = v[:2 * k].reshape(2, k)
    phi /= math.sqrt(np.sum(np.tile(l2_weights(n), 2) * phi.ravel() ** 2))
    return phi if phi[0, n + 1] >= 0 else -phi


def _branch_tangent(shape, free, metric, previous):
    """Unit tangent (metric norm) of the branch at a steady shape, in y = ([X, Z], q):
    the null vector of [∂H/∂u, ∂H/∂q] restricted to ``free``, signed along ``previous``."""
    k = shape.x.shape[1]
    _, dh, dq, _ = steady_jacobian(shape.x, shape.slide, shape.q, shape.w)
    mat = np.hstack([dh[np.ix_(free, free)], dq[free, None]])
    null = np.linalg.svd(mat)[2][-1]
    full = np.zeros(2 * k + 3)
    full[free] = null[:-1]
    t = np.concatenate([full[:2 * k], [null[-1]]])
    t /= math.sqrt(np.sum(metric * t ** 2))
    return t if np.sum(metric * t * previous) >= 0 else -t


def continue_branch(n, q_max, w=DEFAULT_W, side=1, q_min=0.0, max_points=400, step_max=None,
                    stop_after_fold=False):
    """Pseudo-arclength continuation of the steady shapes from the circle at q_c (module
    docstring), on one side of the circle, until q leaves [q_min, q_max] (or, with
    ``stop_after_fold``, two points after q first turns back: the largest q is then the
    third point from the end, the fold between its neighbours).  Steps (in the norm of (x, q)) grow up to
    ``step_max`` (default STEP_MAX) while Newton needs ≤ 3 iterations, and halve when it
    fails or a guard rejects the point."""
    step_max = STEP_MAX if step_max is None else float(step_max)
    n = validation.check_integer("n", n, 4)
    q_max = validation.check_real("q_max", q_max)
    k = 2 * n + 1
    wts = np.tile(l2_weights(n), 2)
    free = mirror_symmetric_index(n)
    qc = critical_q(n, "in-plane", 90.0, w)
    phi = _symmetric_null_vector(n, qc, w)
    x_c = inclined_circle(n, math.pi / 2)
    xp_c = x_c[list(PLANE)].ravel()
    a_phi = wts * phi.ravel()

    def off_circle(h):
        out = newton(x_c + planar_state(n, h * phi), 0.0, qc, w,
                      extra=(a_phi, 0.0, a_phi @ xp_c + h), x_ref=x_c, free=free)
        if out is None:
            raise ValueError(f"no steady shape at amplitude {h} off the circle (n = {n})")
        return out

    plus, minus = off_circle(START_AMPLITUDE), off_circle(-START_AMPLITUDE)
    plus2, minus2 = off_circle(2 * START_AMPLITUDE), off_circle(-2 * START_AMPLITUDE)
    # q(h) = q_c + q1 h + q2 h² + ...: the even part, Richardson-extrapolated to h = 0
    q_bif = (4.0 * (plus[2] + minus[2]) - (plus2[2] + minus2[2])) / 6.0
    shapes = [steady_shape(x_c, 0.0, qc, w, 0)]
    first = plus if side > 0 else minus
    shapes.append(steady_shape(first[0], first[1], first[2], w, first[3]))
    metric = np.concatenate([wts, [1.0]])
    ys = [np.concatenate([xp_c, [qc]]), np.concatenate([first[0][list(PLANE)].ravel(), [first[2]]])]
    tangent = _branch_tangent(shapes[-1], free, metric, ys[-1] - ys[-2])
    step = STEP_FIRST
    while len(shapes) < max_points and q_min <= shapes[-1].q <= q_max:
        pred = ys[-1] + step * tangent
        a = metric * tangent
        out = newton(planar_state(n, pred[:-1].reshape(2, k)), shapes[-1].slide, pred[-1], w,
                      extra=(a[:-1], a[-1], a @ pred), x_ref=shapes[-1].x, free=free)
        if out is not None:
            y_new = np.concatenate([out[0][list(PLANE)].ravel(), [out[2]]])
            shape = steady_shape(out[0], out[1], out[2], w, out[3])
            new_tangent = _branch_tangent(shape, free, metric, tangent)
            # reject a corrector that wandered off (e.g. onto the circle's branch) or a turn
            # too sharp for the step
            if (math.sqrt(np.sum(metric * (y_new - pred) ** 2)) > 0.5 * step
                    or np.sum(metric * new_tangent * tangent) < 0.9):
                out = None
        if out is None:
            step *= 0.5
            if step < STEP_MIN:
                break
            continue
        shapes.append(shape)
        ys.append(y_new)
        tangent = new_tangent
        if stop_after_fold and len(shapes) > 3 and shapes[-1].q < shapes[-2].q < shapes[-3].q:
            break
        if out[3] <= 3:
            step = min(step_max, 1.5 * step)
    return Branch(n=n, w=float(w), q_bifurcation=float(q_bif), q_circle=float(qc),
                  null_vector=phi, shapes=shapes, side=int(np.sign(side)))


# ---------------------------------------------------------------- the branch as a table
#: Row fields of :func:`branch_rows` (the CLI's JSON and :func:`steady_branch`).
ROW_FIELDS = ("q", "aspect_ratio", "side", "stable_in_plane", "stable_out_of_plane",
              "leading_in_plane_real", "leading_in_plane_imag",
              "leading_out_of_plane_real", "leading_out_of_plane_imag",
              "velocity_z", "length_error", "residual")


def _row(shape, side):
    spec = stability(shape)
    lin, lout = spec["leading_in_plane"], spec["leading_out_of_plane"]
    return dict(q=shape.q, aspect_ratio=shape.aspect_ratio, side=side,
                stable_in_plane=bool(lin.real < -STABILITY_TOL),
                stable_out_of_plane=bool(lout.real < -STABILITY_TOL),
                leading_in_plane_real=lin.real, leading_in_plane_imag=lin.imag,
                leading_out_of_plane_real=lout.real, leading_out_of_plane_imag=lout.imag,
                velocity_z=float(shape.velocity[2]), length_error=shape.length_error,
                residual=shape.residual)


def branch_rows(n, q_max, w=DEFAULT_W, q_min=None):
    """Both sides of the branch as rows (``ROW_FIELDS``), in arclength order: the side
    through q < q_c (side -1 of the rows, reversed, ending at the circle), the circle
    (side 0), then the side through q > q_c (side +1).

    ``side`` follows q near the circle, not the sign of φ: +1 is the half that leaves
    towards q > q_c.  Returns (rows, branches) with branches the two :class:`Branch`.
    """
    halves = [continue_branch(n, q_max, w, side=s, q_min=q_min if q_min is not None else 0.0)
              for s in (1, -1)]
    up, down = sorted(halves, key=lambda b: b.shapes[1].q, reverse=True)
    rows = [_row(s, -1) for s in down.shapes[:0:-1]]
    rows.append(_row(up.shapes[0], 0))
    rows += [_row(s, 1) for s in up.shapes[1:]]
    return rows, (up, down)


def rate_crossing(guess, q_lo, q_hi, tol, sector="out_of_plane"):
    """brentq on the leading Re σ of ``sector`` (out_of_plane or in_plane) of the steady
    shapes at q in [q_lo, q_hi] (Newton in the mirror-symmetric subspace from the last
    shape solved)."""
    state = {"x": guess.x, "w": guess.w}

    def rate(q):
        shape = solve_steady(state["x"], q, state["w"], symmetric=True)
        state["x"] = shape.x
        return stability(shape)[f"leading_{sector}"].real

    return float(brentq(rate, q_lo, q_hi, xtol=tol, rtol=4 * np.finfo(float).eps))


def q_loss_out_of_plane(rows, shapes, tol=1e-10):
    """First q on the in-plane-stable part of the branch (from the circle on) where the
    leading out-of-plane Re σ crosses zero, refined by brentq on steady shapes solved at
    intermediate q; None if no crossing.  ``rows`` (``ROW_FIELDS``) and ``shapes`` of
    the half towards q > q_c, in arclength order from the circle."""
    for i in range(1, len(rows)):
        a, b = rows[i - 1], rows[i]
        if not (a["stable_in_plane"] or i == 1):
            continue
        if a["leading_out_of_plane_real"] < 0.0 <= b["leading_out_of_plane_real"]:
            return rate_crossing(shapes[i], a["q"], b["q"], tol)
    return None


def out_of_plane_loss_near(shape, n, q_lo, q_hi, tol=1e-10):
    """q_loss_out_of_plane at truncation n, from a steady shape of another truncation
    near it (``spectral.resize``; a bracket [q_lo, q_hi] of the crossing at n): a quick
    way through a convergence study in n without continuing from the circle each time."""
    guess = solve_steady(spectral.resize(shape.x, n), shape.q, shape.w, symmetric=True)
    return rate_crossing(guess, q_lo, q_hi, tol)


def upper_half(n, q_max, w=DEFAULT_W, step_max=None, stop_after_fold=False):
    """The half of the branch that leaves the circle towards q > q_c (in-plane stable),
    found by a three-point probe of each side, then continued (``continue_branch``)."""
    for side in (-1, 1):
        probe = continue_branch(n, q_max, w, side=side, max_points=3, step_max=step_max)
        if len(probe.shapes) > 2 and probe.shapes[2].q > probe.shapes[0].q:
            return continue_branch(n, q_max, w, side=side, step_max=step_max,
                                   stop_after_fold=stop_after_fold)
    raise ValueError(f"no half of the branch leaves towards q > q_c at n = {n}")


def steady_branch(n=12, q_max=25.0, w=DEFAULT_W, q_min=None):
    """The branch of steady in-plane shapes as a pandas DataFrame (columns ``ROW_FIELDS``),
    for figures (the paper's Fig. 8: terminal aspect ratio against q, stable parts solid).

    ``frame.attrs``: n, w, q_bifurcation (measured on the branch), q_circle (the circle's
    in-plane threshold) and q_loss_out_of_plane (None if none below q_max).
    """
    import pandas as pd

    result = branch_summary(n, q_max, w, q_min)
    frame = pd.DataFrame(result["branch"], columns=list(ROW_FIELDS))
    frame.attrs.update({key: value for key, value in result.items() if key != "branch"})
    return frame


@functools.lru_cache(maxsize=4)
def steady_branch_to(q_max):
    """The local model's steady branch at n = 12 up to ``q_max`` (:func:`steady_branch`),
    computed once per process for each ``q_max``."""
    return steady_branch(n=12, q_max=q_max)


def branch_summary(n=12, q_max=25.0, w=DEFAULT_W, q_min=None):
    """The CLI's JSON object: n, w, q_bifurcation, q_circle, q_loss_out_of_plane, branch."""
    n = validation.check_integer("n", n, 4)
    q_max = validation.check_real("q_max", q_max)
    w = validation.check_real("w", w, low=0.0, low_open=True)
    rows, (up, down) = branch_rows(n, q_max, w, q_min)
    upper = [r for r in rows if r["side"] >= 0]
    q_loss = q_loss_out_of_plane(upper, up.shapes)
    return dict(n=n, w=w, q_bifurcation=up.q_bifurcation, q_circle=up.q_circle,
                q_loss_out_of_plane=q_loss, branch=rows)


