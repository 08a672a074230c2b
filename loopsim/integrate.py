"""Adaptive time integration in Numba: tableau, one step, controller, driver.

A method is data (its tableau) plus one function that attempts a step.  The
driver :func:`integrate` owns everything else: error control with scipy's
meaning of ``rtol``/``atol``, accept/reject, step-size bounds, the step
budget, output at requested times and the status code.  It never raises:
failures come back as a status (see ``STATUS_NAMES``).

The right-hand side comes from ``problems.rhs(problem, y, dydt)``, which is
specialised on the problem's type at compile time, so the same compiled
driver code serves the loop and the closed-form test problems.

Adding a scheme: give it a method id in ``METHODS``, a step function with the
signature of :func:`rkf45_attempt` and a branch in :func:`_attempt`; every
test parametrised over ``METHODS`` then covers it.
"""
import collections

import numba
import numpy as np

from . import radau
from .config import JIT
from .problems import constraint_error, jacobian, rhs, steady_invariants

# ---- status codes --------------------------------------------------------
OK = 0
STEP_BUDGET = 1
STEP_UNDERFLOW = 2
NON_FINITE = 3
LENGTH_ERROR = 4
STEADY = 5  # success: stopped early in a steady terminal state
SUCCESS = (OK, STEADY)
STATUS_NAMES = {
    OK: "ok",
    STEP_BUDGET: "step budget exhausted",
    STEP_UNDERFLOW: "step size underflow",
    NON_FINITE: "non-finite state",
    LENGTH_ERROR: "length error too large",
    STEADY: "ok",
}
#: Why a run stopped, per status.
STOP_REASONS = {**STATUS_NAMES, OK: "t_end", STEADY: "steady"}

#: Consecutive quiet check intervals that make a steady state.
STEADY_WINDOWS = 2

StepOptions = collections.namedtuple(
    "StepOptions",
    "rtol atol first_step min_step max_step max_steps constraint_tol steady_interval steady_tol",
)

# ---- methods ---------------------------------------------------------------
RKF45 = 0
RADAU5 = 1
METHODS = {"rkf45": RKF45, "radau5": RADAU5}

# Runge–Kutta–Fehlberg 4(5): E. Fehlberg, NASA TR R-315 (1969), Table III.
# We advance with the 5th-order weights (local extrapolation) and use the
# difference to the embedded 4th-order weights as the error estimate.
RKF45_C = np.array([0.0, 1 / 4, 3 / 8, 12 / 13, 1.0, 1 / 2])
RKF45_A = np.array(
    [
        [0.0, 0.0, 0.0, 0.0, 0.0],
        [1 / 4, 0.0, 0.0, 0.0, 0.0],
        [3 / 32, 9 / 32, 0.0, 0.0, 0.0],
        [1932 / 2197, -7200 / 2197, 7296 / 2197, 0.0, 0.0],
        [439 / 216, -8.0, 3680 / 513, -845 / 4104, 0.0],
        [-8 / 27, 2.0, -3544 / 2565, 1859 / 4104, -11 / 40],
    ]
)
RKF45_B5 = np.array([16 / 135, 0.0, 6656 / 12825, 28561 / 56430, -9 / 50, 2 / 55])
RKF45_B4 = np.array([25 / 216, 0.0, 1408 / 2565, 2197 / 4104, -1 / 5, 0.0])
RKF45_E = RKF45_B5 - RKF45_B4
RKF45_ERROR_ORDER = 4  # the embedded estimate is O(h^5): factor err^(-1/5)
RKF45_STAGES = 6

# ---- step-size controller (same constants as scipy.integrate.RK45) --------
SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 10.0


@numba.njit(**JIT)
def rms_error_norm(err, y, y_new, rtol, atol):
    """sqrt(mean((err / (atol + rtol max(|y|, |y_new|)))²)), as scipy."""
    acc = 0.0
    for i in range(y.shape[0]):
        scale = atol + rtol * max(abs(y[i]), abs(y_new[i]))
        acc += (err[i] / scale) ** 2
    return np.sqrt(acc / y.shape[0])


@numba.njit(**JIT)
def step_factor(err_norm, error_order):
    """Step-size factor SAFETY err^(-1/(p+1)), clipped to [MIN_FACTOR, MAX_FACTOR]."""
    if err_norm == 0.0:
        return MAX_FACTOR
    if not np.isfinite(err_norm):
        return MIN_FACTOR
    return min(MAX_FACTOR, max(MIN_FACTOR, SAFETY * err_norm ** (-1.0 / (error_order + 1))))


@numba.njit(**JIT)
def rkf45_attempt(problem, y, h, k, stage, y_new, err):
    """One Fehlberg step from y with step h: y_new (5th order) and err = y5 - y4.

    k[0] must hold f(y) on entry; k[1..5] and ``stage`` are overwritten.
    Returns the number of right-hand-side evaluations made (5).
    """
    ny = y.shape[0]
    for s in range(1, RKF45_STAGES):
        for i in range(ny):
            acc = 0.0
            for j in range(s):
                acc += RKF45_A[s, j] * k[j, i]
            stage[i] = y[i] + h * acc
        rhs(problem, stage, k[s])
    for i in range(ny):
        acc5 = 0.0
        acce = 0.0
        for j in range(RKF45_STAGES):
            acc5 += RKF45_B5[j] * k[j, i]
            acce += RKF45_E[j] * k[j, i]
        y_new[i] = y[i] + h * acc5
        err[i] = h * acce
    return RKF45_STAGES - 1


@numba.njit(**JIT)
def _attempt(method, problem, y, h, k, stage, y_new, err):
    """Dispatch one step attempt to the chosen method."""
    return rkf45_attempt(problem, y, h, k, stage, y_new, err)


@numba.njit(**JIT)
def _error_order(method):
    return RKF45_ERROR_ORDER


@numba.njit(**JIT)
def _all_finite(a):
    for v in a.flat:
        if not np.isfinite(v):
            return False
    return True


@numba.njit(**JIT)
def initial_step(problem, y0, f0, rtol, atol, error_order, h_max):
    """Starting step by the Hairer–Nørsett–Wanner heuristic (as scipy's)."""
    ny = y0.shape[0]
    d0 = 0.0
    d1 = 0.0
    for i in range(ny):
        scale = atol + rtol * abs(y0[i])
        d0 += (y0[i] / scale) ** 2
        d1 += (f0[i] / scale) ** 2
    d0 = np.sqrt(d0 / ny)
    d1 = np.sqrt(d1 / ny)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    y1 = y0 + h0 * f0
    f1 = np.empty(ny)
    rhs(problem, y1, f1)
    d2 = 0.0
    for i in range(ny):
        scale = atol + rtol * abs(y0[i])
        d2 += ((f1[i] - f0[i]) / scale) ** 2
    d2 = np.sqrt(d2 / ny) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / (error_order + 1))
    return min(100.0 * h0, h1, h_max)


def step_options(rtol, atol, first_step=None, min_step=0.0, max_step=np.inf,
                 max_steps=1_000_000, constraint_tol=np.inf, steady_interval=0.0,
                 steady_tol=0.0):
    """Driver options (scipy names where they exist) as a ``StepOptions`` tuple.

    first_step: None selects the starting step automatically.
    constraint_tol: stop with LENGTH_ERROR once |constraint_error| exceeds it.
    steady_interval, steady_tol: at the first accepted step at least
    ``steady_interval`` after the previous check, compare the problem's
    invariants (``problems.steady_invariants``) with their values there; when
    no invariant changed by more than ``steady_tol`` per ``steady_interval``
    (the change is scaled by steady_interval / elapsed time, so long implicit
    steps are judged like short ones) at STEADY_WINDOWS consecutive checks,
    stop with status STEADY.  steady_interval <= 0 disables the check.
    """
    return StepOptions(float(rtol), float(atol), -1.0 if first_step is None else float(first_step),
                       float(min_step), float(max_step), int(max_steps), float(constraint_tol),
                       float(steady_interval), float(steady_tol))


@numba.njit(**JIT)
def integrate(method, problem, y0, t0, t_end, t_out, options, y_out):
    """Integrate dy/dt = rhs(problem, y) from t0 to t_end with ``options`` (:func:`step_options`).

    t_out: sorted output times in [t0, t_end]; the state at t_out[i] is written
    to y_out[i] (steps are shortened to land on them exactly).  Rows of
    y_out for times not reached are left untouched.

    Returns (status, t, y, steps_accepted, steps_rejected, rhs_evals,
    max_constraint_error), the last the largest |constraint_error| seen at
    accepted steps (for a loop: the worst transient relative length error).
    """
    if method == RADAU5:
        return _integrate_radau(problem, y0, t0, t_end, t_out, options, y_out)
    return _integrate_explicit(method, problem, y0, t0, t_end, t_out, options, y_out)


@numba.njit(**JIT)
def _record_start(problem, y, t0, t_out, y_out, options):
    """Outputs at t0 and the initial monitor state (i_out, next_check, invariants, quiet)."""
    i_out = 0
    while i_out < t_out.shape[0] and t_out[i_out] <= t0:
        y_out[i_out] = y
        i_out += 1
    return i_out, t0 + options.steady_interval, steady_invariants(problem, y), 0


@numba.njit(**JIT)
def _landing(t, h, t_end, t_out, i_out):
    """Step to try from t: h, shortened to land exactly on the next output time or t_end
    (or stretched by up to 1e-8 relative rather than leave a sliver).  Returns (h_try, clipped, t_stop)."""
    t_stop = t_end
    if i_out < t_out.shape[0] and t_out[i_out] < t_stop:
        t_stop = t_out[i_out]
    if t + h * (1.0 + 1e-8) >= t_stop:
        return t_stop - t, True, t_stop
    return h, False, t_stop


@numba.njit(**JIT)
def _monitor(problem, t, y, t_end, t_out, y_out, options, i_out, worst, next_check, previous,
             quiet):
    """After an accepted step: length error, outputs, steady state.

    Returns (status or -1 to go on, i_out, worst, next_check, previous, quiet).
    """
    worst = max(worst, abs(constraint_error(problem, y)))
    if worst > options.constraint_tol:
        return LENGTH_ERROR, i_out, worst, next_check, previous, quiet
    while i_out < t_out.shape[0] and t_out[i_out] <= t:
        y_out[i_out] = y
        i_out += 1
    if options.steady_interval > 0.0 and t >= next_check and t < t_end:
        current = steady_invariants(problem, y)
        # change per steady_interval, whatever the steps' length since the last check
        elapsed = t - (next_check - options.steady_interval)
        change = max_abs_difference(current, previous) * options.steady_interval / elapsed
        quiet = quiet + 1 if change <= options.steady_tol else 0
        if quiet >= STEADY_WINDOWS:
            return STEADY, i_out, worst, next_check, current, quiet
        previous = current
        next_check = t + options.steady_interval
    return -1, i_out, worst, next_check, previous, quiet


@numba.njit(**JIT)
def _stop_check(options, n_steps, h, t, y):
    """Status that ends the run before the next attempt, or -1."""
    if n_steps >= options.max_steps:
        return STEP_BUDGET
    if h < max(options.min_step, 10.0 * np.finfo(np.float64).eps * abs(t)):
        return STEP_UNDERFLOW if _all_finite(y) else NON_FINITE
    return -1


@numba.njit(**JIT)
def _integrate_explicit(method, problem, y0, t0, t_end, t_out, options, y_out):
    """Driver for the explicit embedded Runge–Kutta methods (see :func:`integrate`)."""
    rtol, atol = options.rtol, options.atol
    ny = y0.shape[0]
    y = y0.copy()
    y_new = np.empty(ny)
    err = np.empty(ny)
    stage = np.empty(ny)
    k = np.empty((RKF45_STAGES, ny))
    order = _error_order(method)
    n_acc = 0
    n_rej = 0
    n_rhs = 1
    worst = 0.0
    t = t0
    rhs(problem, y, k[0])
    if not _all_finite(k[0]) or not _all_finite(y):
        return NON_FINITE, t, y, n_acc, n_rej, n_rhs, worst
    i_out, next_check, previous, quiet = _record_start(problem, y, t0, t_out, y_out, options)
    if options.first_step > 0.0:
        h = min(options.first_step, options.max_step)
    else:
        h = initial_step(problem, y, k[0], rtol, atol, order, options.max_step)
        n_rhs += 1
    while t < t_end:
        stop = _stop_check(options, n_acc + n_rej, h, t, y)
        if stop >= 0:
            return stop, t, y, n_acc, n_rej, n_rhs, worst
        h_try, clipped, t_stop = _landing(t, h, t_end, t_out, i_out)
        n_rhs += _attempt(method, problem, y, h_try, k, stage, y_new, err)
        err_norm = rms_error_norm(err, y, y_new, rtol, atol)
        if not (err_norm <= 1.0):  # also rejects NaN
            n_rej += 1
            h = h_try * step_factor(err_norm, order)
            continue
        n_acc += 1
        t = t_stop if clipped else t + h_try
        y[:] = y_new
        rhs(problem, y, k[0])
        n_rhs += 1
        if not _all_finite(k[0]):
            return NON_FINITE, t, y, n_acc, n_rej, n_rhs, worst
        stop, i_out, worst, next_check, previous, quiet = _monitor(
            problem, t, y, t_end, t_out, y_out, options, i_out, worst, next_check, previous, quiet)
        if stop >= 0:
            return stop, t, y, n_acc, n_rej, n_rhs, worst
        # a step shortened to hit an output time says nothing about the next h
        factor = step_factor(err_norm, order)
        h = min(options.max_step, max(h, h_try * factor) if clipped else h_try * factor)
    return OK, t, y, n_acc, n_rej, n_rhs, worst


@numba.njit(**JIT)
def _radau_factor(h, h_old, err_norm, err_old):
    """Predictive (Gustafsson) step factor, as scipy's Radau; before the safety factor."""
    multiplier = 1.0
    if err_old > 0.0 and h_old > 0.0 and err_norm > 0.0:
        multiplier = h / h_old * (err_old / err_norm) ** 0.25
    if err_norm == 0.0:
        return MAX_FACTOR
    return min(1.0, multiplier) * err_norm ** -0.25


@numba.njit(**JIT)
def _integrate_radau(problem, y0, t0, t_end, t_out, options, y_out):
    """Driver for Radau IIA (order 5) with simplified Newton (see ``radau``).

    Jacobian and LU reuse follow scipy's Radau: the LU factors are kept
    while h does not change (h is held unless it should grow by ≥ 1.2 or
    shrink), the Jacobian is refreshed after a slowly converging Newton
    iteration or when Newton fails with a stale one; a failed Newton halves h.
    """
    rtol, atol = options.rtol, options.atol
    n = y0.shape[0]
    y = y0.copy()
    f = np.empty(n)
    y_new = np.empty(n)
    err = np.empty(n)
    scale = np.empty(n)
    work_y = np.empty(n)
    work_f = np.empty(n)
    real_rhs = np.empty(n)
    complex_rhs = np.empty(n, dtype=np.complex128)
    z = np.zeros((3, n))
    poly = np.zeros((3, n))  # collocation polynomial of the last accepted step
    w = np.empty((3, n))
    fz = np.empty((3, n))
    jac = np.empty((n, n))
    lu_real = np.empty((n, n))
    lu_complex = np.empty((n, n), dtype=np.complex128)
    piv_real = np.empty(n, dtype=np.int64)
    piv_complex = np.empty(n, dtype=np.int64)
    n_acc = 0
    n_rej = 0
    worst = 0.0
    t = t0
    rhs(problem, y, f)
    n_rhs = 1
    if not _all_finite(f) or not _all_finite(y):
        return NON_FINITE, t, y, n_acc, n_rej, n_rhs, worst
    i_out, next_check, previous, quiet = _record_start(problem, y, t0, t_out, y_out, options)
    n_rhs += jacobian(problem, y, f, jac, work_y, work_f)
    jac_current = True
    if options.first_step > 0.0:
        h = min(options.first_step, options.max_step)
    else:
        h = initial_step(problem, y, f, rtol, atol, radau.ERROR_ORDER, options.max_step)
        n_rhs += 1
    newton_tol = max(10.0 * np.finfo(np.float64).eps / rtol, min(0.03, rtol ** 0.5))
    h_lu = -1.0
    h_old = -1.0  # last accepted step (-1: none yet)
    err_old = -1.0
    rejected = False
    while t < t_end:
        stop = _stop_check(options, n_acc + n_rej, h, t, y)
        if stop >= 0:
            return stop, t, y, n_acc, n_rej, n_rhs, worst
        h_try, clipped, t_stop = _landing(t, h, t_end, t_out, i_out)
        for i in range(n):
            scale[i] = atol + rtol * abs(y[i])
        converged = False
        iterations = 0
        rate = -1.0
        while True:
            if h_try != h_lu:
                radau.newton_matrices(jac, h_try, lu_real, piv_real, lu_complex, piv_complex)
                h_lu = h_try
            if h_old > 0.0:
                radau.extrapolated_guess(poly, h_try / h_old, z)
            else:
                z[:] = 0.0
            converged, iterations, rate = radau.solve_collocation(
                problem, y, h_try, z, scale, newton_tol, lu_real, piv_real, lu_complex,
                piv_complex, w, fz, work_y, real_rhs, complex_rhs)
            n_rhs += 3 * iterations
            if converged or jac_current:
                break
            n_rhs += jacobian(problem, y, f, jac, work_y, work_f)
            jac_current = True
            h_lu = -1.0
        if not converged:
            n_rej += 1
            rejected = True
            h = 0.5 * h_try
            continue
        for i in range(n):
            y_new[i] = y[i] + z[2, i]
            scale[i] = atol + rtol * max(abs(y[i]), abs(y_new[i]))
        radau.error_estimate(f, z, h_try, lu_real, piv_real, err)
        err_norm = radau._scaled_rms(err, scale)
        if rejected and err_norm > 1.0:  # Hairer's second filtering after a rejection
            for i in range(n):
                work_y[i] = y[i] + err[i]
            rhs(problem, work_y, work_f)
            n_rhs += 1
            radau.error_estimate(work_f, z, h_try, lu_real, piv_real, err)
            err_norm = radau._scaled_rms(err, scale)
        safety = 0.9 * (2 * radau.NEWTON_MAXITER + 1) / (2 * radau.NEWTON_MAXITER + iterations)
        if not (err_norm <= 1.0):
            n_rej += 1
            rejected = True
            h = h_try * max(MIN_FACTOR, safety * _radau_factor(h_try, h_old, err_norm, err_old))
            continue
        n_acc += 1
        rejected = False
        t = t_stop if clipped else t + h_try
        y[:] = y_new
        rhs(problem, y, f)
        n_rhs += 1
        if not _all_finite(f):
            return NON_FINITE, t, y, n_acc, n_rej, n_rhs, worst
        stop, i_out, worst, next_check, previous, quiet = _monitor(
            problem, t, y, t_end, t_out, y_out, options, i_out, worst, next_check, previous, quiet)
        if stop >= 0:
            return stop, t, y, n_acc, n_rej, n_rhs, worst
        recompute_jac = iterations > radau.JACOBIAN_ITERATIONS and rate > radau.JACOBIAN_RATE
        factor = min(MAX_FACTOR, safety * _radau_factor(h_try, h_old, err_norm, err_old))
        if not recompute_jac and factor < 1.2:
            factor = 1.0  # keep h, and with it the LU factors
        if recompute_jac:
            n_rhs += jacobian(problem, y, f, jac, work_y, work_f)
            jac_current = True
            h_lu = -1.0
        else:
            jac_current = False
        radau.collocation_polynomial(z, poly)
        h_old = h_try
        err_old = err_norm
        proposal = h_try * factor
        h = min(options.max_step, max(h, proposal) if clipped else proposal)
    return OK, t, y, n_acc, n_rej, n_rhs, worst


@numba.njit(**JIT)
def max_abs_difference(a, b):
    worst = 0.0
    for i in range(a.shape[0]):
        worst = max(worst, abs(a[i] - b[i]))
    return worst
