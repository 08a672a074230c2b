"""Radau IIA (order 5) building blocks in Numba: tableau, LU, Jacobian, Newton.

The 3-stage Radau IIA collocation method (Hairer & Wanner, *Solving ODEs II*,
§IV.8) solves, for the stage increments Z_i = Y_i − y,

    Z = h (A ⊗ I) F(y + Z),      y_new = y + Z_3,

by simplified Newton iterations.  With A⁻¹ = T Λ T⁻¹, Λ = diag(μ_r, [[α, β],
[−β, α]]), the Newton matrix decouples into one real system (μ_r/h − J) and
one complex system (μ_c/h − J), μ_c = α − iβ, each LU-factorised once and
reused while h and J stay.  The embedded error estimate is Hairer's
(an order-3 companion using f(y)), filtered through the real LU.  The
transformation T and the error weights are computed here from A, not typed
in, and are tested as data.

J comes from ``models.jacobian`` (exact for every model; for the loop it is
``models.local_sbt.loop_jacobian``).  Jacobian and LU reuse follow scipy's
Radau (Hairer's policies): the LU factors are kept while h does not change (h
is held unless it should grow by ≥ HOLD_FACTOR or shrink), the Jacobian is
refreshed after a slowly converging Newton iteration or when Newton fails
with a stale one; a failed Newton cuts h by NEWTON_FAILURE_FACTOR.  Unlike
theirs, the Jacobian is not taken at y but inside the step it serves, at
JACOBIAN_POINT of it on the last step's collocation polynomial (at y only on the
first step): on a tumbling loop J moves enough within a step for the frozen-J
iteration to diverge in the high modes (measurements at JACOBIAN_POINT).

Step control (:func:`step_proposal`) takes the smaller of two limits.  The
error limit is Gustafsson's predictive controller on the filtered estimate
(its second filtering on the first step and after every rejection, as
Hairer's radau5).  The Newton limit keeps h where
the simplified Newton iteration converges: at a loose rtol the error allows
steps at which it no longer contracts (at (150, 45°, 16), t ≤ 2, rtol 1e-3,
295 of 298 rejections were Newton failures, most followed by a half step, a
doubling and the same failure), so the step grows at most to where the
contraction rate is predicted to reach NEWTON_RATE_TARGET, and not at all
right after a rejection (Hairer).  Only rates measured from a correction well above
its rounding count for that limit (NOISE_MARGIN): nearer, the corrections are noise,
whose ratio (0.3-0.6 near a steady state at rtol 1e-9) would shrink h at every step
(rtol 1e-9, atol 1e-12 then cost 4.2x rtol 1e-8 at (150, 45°, 21), t <= 10).  The error
weights atol + rtol |y_i| are floored at the rounding error a Newton correction carries,
relative to the Newton tolerance (ROUNDOFF_FLOOR): with a tiny atol, components near
zero otherwise ask the iteration for accuracy below rounding, and the run stalls in
Newton failures.
Everything writes into caller-owned arrays.
"""
import collections

import numpy as np

from ..jit import kernel
from ..models import jacobian, rhs
from .base import advance, attempt, dense_output, implements, start, statistics
from .control import EPS, MAX_FACTOR, MIN_FACTOR, SAFETY, rms_norm
from ..linalg import PIVOT_DTYPE, lu_factor, lu_solve

_S6 = np.sqrt(6.0)
C = np.array([(4.0 - _S6) / 10.0, (4.0 + _S6) / 10.0, 1.0])
A = np.array([
    [(88.0 - 7.0 * _S6) / 360.0, (296.0 - 169.0 * _S6) / 1800.0, (-2.0 + 3.0 * _S6) / 225.0],
    [(296.0 + 169.0 * _S6) / 1800.0, (88.0 + 7.0 * _S6) / 360.0, (-2.0 - 3.0 * _S6) / 225.0],
    [(16.0 - _S6) / 36.0, (16.0 + _S6) / 36.0, 1.0 / 9.0],
])
ERROR_ORDER = 3  # the embedded estimate is O(h^4): factor err^(-1/4)
#: Newton iterations per attempt, as Hairer's radau5 (scipy: 6).
NEWTON_MAXITER = 7
#: Refresh the Jacobian after an accepted step whose Newton iteration took more
#: than JACOBIAN_ITERATIONS iterations at a contraction rate above JACOBIAN_RATE.
JACOBIAN_ITERATIONS = 2
JACOBIAN_RATE = 1e-3
#: Keep h (and with it the LU factors) unless the controller asks for at least this growth.
HOLD_FACTOR = 1.2
#: Step-size factor after a Newton iteration that failed to converge.
NEWTON_FAILURE_FACTOR = 0.5
#: Newton tolerance max(NEWTON_TOL_FLOOR eps / rtol, min(NEWTON_TOL_MAX, sqrt(rtol))), as scipy.
#: (A looser one costs accuracy: 0.03 at every rtol made the terminal tilt of (150, 45°,
#: 16) at t = 2 40 times further off at rtol 1e-9, atol 1e-12, for 6% fewer RHS
#: evaluations.)
NEWTON_TOL_FLOOR = 10.0
NEWTON_TOL_MAX = 0.03
#: The Newton limit on the next step (Gustafsson & Söderlind's rate control): after an
#: accepted step whose Newton iteration contracted at rate θ, the next step is at most
#: h (NEWTON_RATE_TARGET / θ)^(1 / NEWTON_RATE_ORDER).  Across the growths after which
#: Newton failed the rate grew like h^2 to h^4 (median exponent 2.0-4.0 in five runs of
#: (150, 45°, 16-21) and (100, 60°, 21) at rtol 1e-3 to 1e-5); order 4 covers most.
NEWTON_RATE_TARGET = 0.2
NEWTON_RATE_ORDER = 4.0
#: Largest growth of the step proposed right after a rejected attempt (Hairer's radau5).
REJECTED_GROWTH = 1.0
#: Error weights are at least ROUNDOFF_FLOOR eps h max|f| / newton_tol: a Newton correction
#: carries the rounding of the right-hand side over the step, about 0.3 eps h max|f|
#: (measured: the corrections of (150, 45°, 21) near its steady state stall there, at
#: every h), and the iteration must see it below its tolerance newton_tol (in units of the
#: weights).  With the floor at 100 eps h max|f| instead, rtol 1e-10, atol 1e-13 rejected
#: 18 319 steps for 40 207 accepted over t <= 10, all Newton failures in the noise; with
#: this floor, 36 for 8 178, at the same terminal tilt to 2e-7 deg.
ROUNDOFF_FLOOR = 1.0
#: A contraction rate counts for the Newton limit only when measured from a correction
#: above NOISE_MARGIN times the corrections' rounding (:func:`rounding_noise`).
NOISE_MARGIN = 10.0
#: Where the Jacobian is evaluated, as a fraction of the step it is for: at the last
#: accepted step's collocation polynomial extrapolated to t + JACOBIAN_POINT h (h the step
#: about to be taken; :func:`jacobian_state`), 0 meaning at y (Hairer's and scipy's
#: radau5).  The stages sit at c = 0.155, 0.645, 1 of the step: a Jacobian there rather
#: than at its start is the one the simplified Newton iteration of that step needs.
#: Measured on the tumbling loop (350, 18°, 32) (benchmarks/bench_tumbling.py): over
#: t in [0, 0.5] and [1, 1.3], nfev 0.56-0.64x at rtol 1e-3 and 0.92-0.93x at 1e-6,
#: Jacobians 0.64-0.79x, priced cost 0.61-0.85x, wall time 0.56-0.91x; at equal end-state
#: error over 0.1 t_u 0.56-0.74x.  On the well-posed cases of bench_step_control.py, 0.83x
#: at equal terminal-tilt error, at most 1 % more RHS evaluations (one F per Jacobian, at
#: its point).  Points from 0.5 to 1 do about as well (docs/studies/development-notes-levers.md).
JACOBIAN_POINT = 0.578

#: The method as data: its error order and the policy constants above.
RadauIIA = collections.namedtuple(
    "RadauIIA", "error_order newton_maxiter jacobian_iterations jacobian_rate hold_factor "
    "newton_failure_factor rate_target rate_order rejected_growth roundoff_floor "
    "jacobian_point")
RADAU5 = RadauIIA(ERROR_ORDER, NEWTON_MAXITER, JACOBIAN_ITERATIONS, JACOBIAN_RATE, HOLD_FACTOR,
                  NEWTON_FAILURE_FACTOR, NEWTON_RATE_TARGET, NEWTON_RATE_ORDER, REJECTED_GROWTH,
                  ROUNDOFF_FLOOR, JACOBIAN_POINT)


def _transformation():
    """T, T⁻¹, μ_r, μ_c with T⁻¹ A⁻¹ T = diag(μ_r, [[α, β], [−β, α]]), μ_c = α − iβ."""
    values, vectors = np.linalg.eig(np.linalg.inv(A))
    real = int(np.argmin(np.abs(values.imag)))
    pair = int(np.argmax(values.imag))  # α + iβ with β > 0
    v = vectors[:, pair]
    t = np.column_stack([vectors[:, real].real, v.real, v.imag])
    t = t / t[2, 0]  # any scaling works; this one makes row 3 of T start with 1
    return t, np.linalg.inv(t), float(values[real].real), complex(values[pair].conjugate())


def _embedded_weights(mu_real):
    """E with err = (μ_r/h − J)⁻¹ (f(y) + Σ E_i Z_i / h) (Hairer's order-3 companion).

    The companion uses b̂_0 = γ0 = 1/μ_r on f(y) and b̂_1..3 from the order
    conditions Σ b̂_i c_i^(k−1) = 1/k, k = 1..3; E = μ_r (b̂ − b) A⁻¹, b = A[2].
    """
    gamma0 = 1.0 / mu_real
    powers = np.vstack([C**k for k in range(3)])
    rhs_k = np.array([1.0, 1.0 / 2.0, 1.0 / 3.0]) - np.array([gamma0, 0.0, 0.0])
    b_hat = np.linalg.solve(powers, rhs_k)
    return mu_real * (b_hat - A[2]) @ np.linalg.inv(A)


T, TI, MU_REAL, MU_COMPLEX = _transformation()
E = _embedded_weights(MU_REAL)
#: Z_i = Σ_k q_k c_i^(k+1): the collocation polynomial's coefficients are q = V⁻¹ Z.
VINV = np.linalg.inv(np.vander(C, 4, increasing=True)[:, 1:])


@kernel
def collocation_polynomial(z, q):
    """q (3, n) with y(t_old + x h) = y_old + Σ_k q_k x^(k+1), from the stage increments z."""
    for k in range(3):
        for i in range(z.shape[1]):
            q[k, i] = VINV[k, 0] * z[0, i] + VINV[k, 1] * z[1, i] + VINV[k, 2] * z[2, i]


@kernel
def extrapolated_guess(q, ratio, z):
    """Newton start for the next step (h_new = ratio · h_old): the last step's collocation
    polynomial evaluated at the new stage times, minus its end value."""
    for r in range(3):
        x = 1.0 + ratio * C[r]
        for i in range(z.shape[1]):
            z[r, i] = (q[0, i] * (x - 1.0) + q[1, i] * (x * x - 1.0)
                       + q[2, i] * (x * x * x - 1.0))


@kernel
def jacobian_state(y, q, ratio, out):
    """out = the last step's collocation polynomial (``q``, step h_old, ending at y) at
    t + ratio h_old: y + Σ_k q_k ((1 + ratio)^(k+1) − 1); out = y for ratio 0."""
    x = 1.0 + ratio
    for i in range(y.shape[0]):
        out[i] = y[i] + (q[0, i] * (x - 1.0) + q[1, i] * (x * x - 1.0)
                         + q[2, i] * (x * x * x - 1.0))


# ---- Newton matrices, iteration and error estimate -----------------------
@kernel
def newton_matrices(jac, h, lu_real, piv_real, lu_complex, piv_complex):
    """Factorise μ_r/h − J and μ_c/h − J."""
    n = jac.shape[0]
    for i in range(n):
        for j in range(n):
            lu_real[i, j] = -jac[i, j]
            lu_complex[i, j] = -jac[i, j]
        lu_real[i, i] += MU_REAL / h
        lu_complex[i, i] += MU_COMPLEX / h
    lu_factor(lu_real, piv_real)
    lu_factor(lu_complex, piv_complex)


@kernel(inline=True)  # in the step attempt: a library of its own would hold the rhs again
def solve_collocation(problem, y, h, z, scale, tol, noise, maxiter, lu_real, piv_real,
                      lu_complex, piv_complex, w, fz, stage, real_rhs, complex_rhs):
    """Simplified Newton for Z = h A F(y + Z), from the guess in z (3, n), updated in place.

    Returns (converged, iterations, rate, limit_rate); 3 RHS evaluations per iteration.
    ``rate`` is the last contraction rate seen; ``limit_rate`` the last one measured from
    a correction above NOISE_MARGIN times ``noise`` (the corrections' rounding, in the
    norm of ``scale``; -1 if none): nearer the noise, the ratio of two corrections says
    nothing of how h affects convergence.
    """
    n = y.shape[0]
    m_real = MU_REAL / h
    m_complex = MU_COMPLEX / h
    for r in range(3):
        for i in range(n):
            w[r, i] = TI[r, 0] * z[0, i] + TI[r, 1] * z[1, i] + TI[r, 2] * z[2, i]
    norm_old = -1.0
    rate = -1.0
    limit_rate = -1.0
    for iteration in range(maxiter):
        for r in range(3):
            for i in range(n):
                stage[i] = y[i] + z[r, i]
            rhs(problem, stage, fz[r])
        for r in range(3):
            for i in range(n):
                if not np.isfinite(fz[r, i]):
                    return False, iteration + 1, rate, limit_rate
        for i in range(n):
            tf0 = TI[0, 0] * fz[0, i] + TI[0, 1] * fz[1, i] + TI[0, 2] * fz[2, i]
            tf1 = TI[1, 0] * fz[0, i] + TI[1, 1] * fz[1, i] + TI[1, 2] * fz[2, i]
            tf2 = TI[2, 0] * fz[0, i] + TI[2, 1] * fz[1, i] + TI[2, 2] * fz[2, i]
            real_rhs[i] = tf0 - m_real * w[0, i]
            complex_rhs[i] = (tf1 + 1j * tf2) - m_complex * (w[1, i] + 1j * w[2, i])
        lu_solve(lu_real, piv_real, real_rhs)
        lu_solve(lu_complex, piv_complex, complex_rhs)
        acc = 0.0
        for i in range(n):
            acc += (real_rhs[i] / scale[i]) ** 2 + (complex_rhs[i].real / scale[i]) ** 2 \
                + (complex_rhs[i].imag / scale[i]) ** 2
        norm = np.sqrt(acc / (3 * n))
        if norm_old >= 0.0:
            rate = norm / norm_old
            if norm_old > NOISE_MARGIN * noise:
                limit_rate = rate
        if rate >= 0.0 and (rate >= 1.0 or
                            rate ** (maxiter - iteration) / (1.0 - rate) * norm > tol):
            return False, iteration + 1, rate, limit_rate
        for i in range(n):
            w[0, i] += real_rhs[i]
            w[1, i] += complex_rhs[i].real
            w[2, i] += complex_rhs[i].imag
        for r in range(3):
            for i in range(n):
                z[r, i] = T[r, 0] * w[0, i] + T[r, 1] * w[1, i] + T[r, 2] * w[2, i]
        if norm == 0.0 or (rate >= 0.0 and rate / (1.0 - rate) * norm < tol):
            return True, iteration + 1, rate, limit_rate
        norm_old = norm
    return False, maxiter, rate, limit_rate


@kernel
def error_estimate(f0, z, h, lu_real, piv_real, out):
    """out = (μ_r/h − J)⁻¹ (f(y) + Σ E_i Z_i / h)."""
    for i in range(f0.shape[0]):
        out[i] = f0[i] + (E[0] * z[0, i] + E[1] * z[1, i] + E[2] * z[2, i]) / h
    lu_solve(lu_real, piv_real, out)


# ---- step control: the error limit and the Newton limit -------------------------
@kernel
def predictive_factor(h, h_old, err_norm, err_old):
    """Gustafsson's predictive step factor, before the safety factor:
    min(1, (h / h_old)(err_old / err)^(1/4)) err^(-1/4)."""
    multiplier = 1.0
    if err_old > 0.0 and h_old > 0.0 and err_norm > 0.0:
        multiplier = h / h_old * (err_old / err_norm) ** 0.25
    if err_norm == 0.0:
        return MAX_FACTOR
    return min(1.0, multiplier) * err_norm ** -0.25


@kernel
def newton_limit(rate, target, order):
    """Largest step factor at which the simplified Newton iteration, seen contracting at
    ``rate`` in the last step, is predicted to contract at ``target``:
    (target / rate)^(1 / order); MAX_FACTOR when no rate was measured (one iteration)."""
    if rate <= 0.0:
        return MAX_FACTOR
    return (target / rate) ** (1.0 / order)


@kernel
def step_proposal(method, controller, safety, rate, rejected, recompute_jac):
    """The next step's factor after an accepted step: the error limit (``controller``,
    Gustafsson's, times ``safety``) capped by MAX_FACTOR, by the Newton limit
    (:func:`newton_limit`) and, right after a rejected attempt, by
    ``method.rejected_growth``; 1 (keep h and the LU factors) when the Jacobian stays
    and the factor is below ``method.hold_factor``."""
    factor = min(MAX_FACTOR, safety * controller,
                 newton_limit(rate, method.rate_target, method.rate_order))
    if rejected:
        factor = min(factor, method.rejected_growth)
    if not recompute_jac and factor < method.hold_factor:
        factor = 1.0
    return factor


@kernel
def rounding_noise(h, f_max, scale):
    """eps h max|f| in the RMS norm weighted by ``scale``: the size of the rounding a
    Newton correction carries (about 0.3 of it, measured)."""
    acc = 0.0
    for i in range(scale.shape[0]):
        acc += (1.0 / scale[i]) ** 2
    return EPS * h * f_max * np.sqrt(acc / scale.shape[0])


@kernel
def error_weights(y, y_new, rtol, atol, floor, scale):
    """scale_i = max(atol + rtol max(|y_i|, |y_new_i|), floor) (``y_new`` may be ``y``)."""
    for i in range(y.shape[0]):
        scale[i] = max(atol + rtol * max(abs(y[i]), abs(y_new[i])), floor)


#: Per-run arrays, and the scalars the policies carry from step to step
#: (indices below, stored as float64).
RadauWork = collections.namedtuple(
    "RadauWork", "scale work_y work_f err real_rhs complex_rhs z poly w fz jac lu_real "
    "lu_complex piv_real piv_complex scalars jac_y jac_f")
(H_LU, H_OLD, ERR_OLD, REJECTED, JAC_CURRENT, NEWTON_TOL, ERR_NORM, RECOMPUTE_JAC, JACOBIANS,
 FACTORISATIONS, JAC_PENDING, H_NEXT) = range(12)


@kernel(inline=True)  # in the step attempt, which held the Jacobian's calls before
def refresh_jacobian(method, work, problem, y, f, h):
    """work.jac = J for a step of size h from y (f = F(y)), at ``method.jacobian_point``
    of it on the last accepted step's collocation polynomial (:func:`jacobian_state`);
    at y before the first accepted step or with jacobian_point 0.  Returns the RHS
    evaluations (J's own, and F at that point)."""
    s = work.scalars
    evals = 0
    if method.jacobian_point > 0.0 and s[H_OLD] > 0.0:
        jacobian_state(y, work.poly, method.jacobian_point * h / s[H_OLD], work.jac_y)
        rhs(problem, work.jac_y, work.jac_f)  # models.jacobian is given F at its point
        evals = 1
    else:
        for i in range(y.shape[0]):
            work.jac_y[i] = y[i]
            work.jac_f[i] = f[i]
    s[JACOBIANS] += 1.0
    return evals + jacobian(problem, work.jac_y, work.jac_f, work.jac, work.work_y, work.work_f)


@implements(start, RadauIIA)
def _radau_start(method, problem, y, f, options):
    n = y.shape[0]
    work = RadauWork(
        np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n),
        np.empty(n, dtype=np.complex128), np.zeros((3, n)), np.zeros((3, n)),
        np.empty((3, n)), np.empty((3, n)), np.empty((n, n)), np.empty((n, n)),
        np.empty((n, n), dtype=np.complex128), np.empty(n, dtype=PIVOT_DTYPE),
        np.empty(n, dtype=PIVOT_DTYPE), np.zeros(12), np.empty(n), np.empty(n))
    s = work.scalars
    s[JAC_PENDING] = 1.0  # the Jacobian at y: the driver's catch-up call evaluates it next
    s[H_LU] = -1.0
    s[H_OLD] = -1.0  # last accepted step (-1: none yet)
    s[ERR_OLD] = -1.0
    s[REJECTED] = 0.0
    s[JAC_CURRENT] = 1.0
    s[NEWTON_TOL] = max(NEWTON_TOL_FLOOR * EPS / options.rtol,
                        min(NEWTON_TOL_MAX, options.rtol ** 0.5))
    return work, 0


@implements(attempt, RadauIIA)
def _radau_attempt(method, work, problem, y, f, h, y_new, options):
    n = y.shape[0]
    s = work.scalars
    if h < 0.0:  # base.CATCH_UP: the Jacobian start or advance asked for, for the next step
        evals = 0
        if s[JAC_PENDING] != 0.0:
            evals = refresh_jacobian(method, work, problem, y, f,
                                     min(s[H_NEXT], options.max_step))
            s[JAC_PENDING] = 0.0
        return True, 0.0, evals
    f_max = 0.0
    for i in range(n):
        f_max = max(f_max, abs(f[i]))
    floor = method.roundoff_floor * EPS * h * f_max / s[NEWTON_TOL]
    error_weights(y, y, options.rtol, options.atol, floor, work.scale)
    noise = rounding_noise(h, f_max, work.scale)
    evals = 0
    while True:
        if h != s[H_LU]:
            newton_matrices(work.jac, h, work.lu_real, work.piv_real, work.lu_complex,
                            work.piv_complex)
            s[H_LU] = h
            s[FACTORISATIONS] += 1.0
        if s[H_OLD] > 0.0:
            extrapolated_guess(work.poly, h / s[H_OLD], work.z)
        else:
            work.z[:] = 0.0
        converged, iterations, rate, limit_rate = solve_collocation(
            problem, y, h, work.z, work.scale, s[NEWTON_TOL], noise, method.newton_maxiter,
            work.lu_real, work.piv_real, work.lu_complex, work.piv_complex, work.w, work.fz,
            work.work_y, work.real_rhs, work.complex_rhs)
        evals += 3 * iterations
        if converged or s[JAC_CURRENT] != 0.0:
            break
        evals += refresh_jacobian(method, work, problem, y, f, h)
        s[JAC_CURRENT] = 1.0
        s[H_LU] = -1.0
    if not converged:
        s[REJECTED] = 1.0
        return False, method.newton_failure_factor * h, evals
    for i in range(n):
        y_new[i] = y[i] + work.z[2, i]
    error_weights(y, y_new, options.rtol, options.atol, floor, work.scale)
    error_estimate(f, work.z, h, work.lu_real, work.piv_real, work.err)
    err_norm = rms_norm(work.err, work.scale)
    first = s[H_OLD] <= 0.0
    if (first or s[REJECTED] != 0.0) and err_norm > 1.0:  # Hairer's second filtering
        for i in range(n):
            work.work_y[i] = y[i] + work.err[i]
        rhs(problem, work.work_y, work.work_f)
        evals += 1
        error_estimate(work.work_f, work.z, h, work.lu_real, work.piv_real, work.err)
        err_norm = rms_norm(work.err, work.scale)
    maxiter = method.newton_maxiter
    safety = SAFETY * (2 * maxiter + 1) / (2 * maxiter + iterations)
    controller = predictive_factor(h, s[H_OLD], err_norm, s[ERR_OLD])
    if not (err_norm <= 1.0):
        s[REJECTED] = 1.0
        return False, h * max(MIN_FACTOR, safety * controller), evals
    rejected = s[REJECTED] != 0.0
    s[REJECTED] = 0.0
    recompute_jac = iterations > method.jacobian_iterations and rate > method.jacobian_rate
    factor = step_proposal(method, controller, safety, limit_rate, rejected, recompute_jac)
    s[ERR_NORM] = err_norm
    s[RECOMPUTE_JAC] = 1.0 if recompute_jac else 0.0
    collocation_polynomial(work.z, work.poly)  # dense output, and the next Newton start
    return True, h * factor, evals


@implements(advance, RadauIIA)
def _radau_advance(method, work, problem, y, f, h, h_proposal):
    s = work.scalars
    if s[RECOMPUTE_JAC] != 0.0:
        s[JAC_PENDING] = 1.0  # evaluated for h_proposal by the driver's catch-up call, next
        s[JAC_CURRENT] = 1.0
        s[H_LU] = -1.0
    else:
        s[JAC_CURRENT] = 0.0
    s[H_OLD] = h
    s[H_NEXT] = h_proposal
    s[ERR_OLD] = s[ERR_NORM]
    return h_proposal, 0


@implements(dense_output, RadauIIA)
def _radau_dense_output(method, work, problem, y_old, f_old, y, f, h, theta, out, options):
    """The collocation polynomial of the step: y_old + Σ_k q_k θ^(k+1) (order 3)."""
    q = work.poly
    for i in range(y.shape[0]):
        out[i] = y_old[i] + theta * (q[0, i] + theta * (q[1, i] + theta * q[2, i]))
    return 0


@implements(statistics, RadauIIA)
def _radau_statistics(method, work):
    return int(work.scalars[JACOBIANS]), int(work.scalars[FACTORISATIONS])
