"""Explicit embedded Runge–Kutta methods: a method is its Butcher tableau.

A :class:`Tableau` holds c, a (strictly lower triangular), the propagating
weights b and the error weights e = b − b̂ (b̂ the embedded weights) and the
order p of the error estimate; the ``attempt`` implementation takes one step of any
tableau.  Adding an explicit method is adding a ``Tableau`` constant and a
name in ``integrators.METHODS``.
"""
import collections

import numpy as np

from ..linalg import copy_into
from ..models import rhs
from .base import advance, attempt, dense_output, implements, start, statistics
from .control import error_scale, rms_norm, step_factor

#: c (s,), a (s, s), b (s,), e (s,) arrays; error_order: p of the O(h^(p+1)) estimate.
Tableau = collections.namedtuple("Tableau", "c a b e error_order")

# Runge–Kutta–Fehlberg 4(5): E. Fehlberg, NASA TR R-315 (1969), Table III.  We
# advance with the 5th-order weights (local extrapolation) and use the
# difference to the embedded 4th-order weights as the error estimate.
RKF45_C = np.array([0.0, 1 / 4, 3 / 8, 12 / 13, 1.0, 1 / 2])
RKF45_A = np.array(
    [
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [1 / 4, 0.0, 0.0, 0.0, 0.0, 0.0],
        [3 / 32, 9 / 32, 0.0, 0.0, 0.0, 0.0],
        [1932 / 2197, -7200 / 2197, 7296 / 2197, 0.0, 0.0, 0.0],
        [439 / 216, -8.0, 3680 / 513, -845 / 4104, 0.0, 0.0],
        [-8 / 27, 2.0, -3544 / 2565, 1859 / 4104, -11 / 40, 0.0],
    ]
)
RKF45_B5 = np.array([16 / 135, 0.0, 6656 / 12825, 28561 / 56430, -9 / 50, 2 / 55])
RKF45_B4 = np.array([25 / 216, 0.0, 1408 / 2565, 2197 / 4104, -1 / 5, 0.0])
RKF45 = Tableau(RKF45_C, RKF45_A, RKF45_B5, RKF45_B5 - RKF45_B4, 4)

#: Per-run scratch: stage derivatives k (s, ny), stage state, error, error scale.
ExplicitWork = collections.namedtuple("ExplicitWork", "k stage err scale")


@implements(start, Tableau)
def _explicit_start(method, problem, y, f, options):
    ny = y.shape[0]
    work = ExplicitWork(np.empty((method.c.shape[0], ny)), np.empty(ny), np.empty(ny),
                        np.empty(ny))
    return work, 0


@implements(attempt, Tableau)
def _explicit_attempt(method, work, problem, y, f, h, y_new, options):
    """One step of the tableau from y (f = F(y)) with step h: y_new = y + h Σ b_j k_j and
    err = h Σ e_j k_j, with k_s = F(y + h Σ_{j<s} a_sj k_j), k_0 = f; accepted when the
    RMS norm of err in the scale atol + rtol max(|y|, |y_new|) is at most 1.

    Overwrites work.k, work.stage, work.err and work.scale; costs s − 1 RHS evaluations.
    With h = ``base.CATCH_UP``: nothing (start and advance leave no work).
    """
    if h < 0.0:
        return True, 0.0, 0
    k = work.k
    stage = work.stage
    copy_into(k[0], f)
    ny = y.shape[0]
    stages = method.c.shape[0]
    for s in range(1, stages):
        for i in range(ny):
            acc = 0.0
            for j in range(s):
                acc += method.a[s, j] * k[j, i]
            stage[i] = y[i] + h * acc
        rhs(problem, stage, k[s])
    for i in range(ny):
        acc_b = 0.0
        acc_e = 0.0
        for j in range(stages):
            acc_b += method.b[j] * k[j, i]
            acc_e += method.e[j] * k[j, i]
        y_new[i] = y[i] + h * acc_b
        work.err[i] = h * acc_e
    error_scale(y, y_new, options.rtol, options.atol, work.scale)
    err_norm = rms_norm(work.err, work.scale)
    return err_norm <= 1.0, h * step_factor(err_norm, method.error_order), stages - 1


@implements(advance, Tableau)
def _explicit_advance(method, work, problem, y, f, h, h_proposal):
    return h_proposal, 0


@implements(dense_output, Tableau)
def _explicit_dense_output(method, work, problem, y_old, f_old, y, f, h, theta, out,
                           options):
    """One extra step of the tableau from y_old of size θh, on the side (an attempt whose
    verdict is ignored): as accurate as the integration itself (a cubic Hermite
    interpolant of the step is only third order: 1e-6 relative errors at rtol 1e-8 on
    the Riccati test).  Costs s − 1 RHS evaluations per output time; the work arrays it
    overwrites are reset by the next attempt."""
    return attempt(method, work, problem, y_old, f_old, theta * h, out, options)[2]


@implements(statistics, Tableau)
def _explicit_statistics(method, work):
    return 0, 0
