"""What every integrator shares: statuses, options, error norm, step-size control, output.

Nothing here knows a method: the driver (``integrators.driver``) calls these
helpers around one method-specific step attempt.

Error control follows scipy's ``solve_ivp``: the error estimate err of a step
from y to y_new is accepted when

    ||err||_rms = sqrt(mean((err_i / (atol + rtol max(|y_i|, |y_new_i|)))²)) ≤ 1,

and the next step is h · clip(SAFETY ||err||^(-1/(p+1)), MIN_FACTOR, MAX_FACTOR)
with p the order of the error estimate.
"""
import collections

import numpy as np

from ..jit import kernel
from ..linalg import copy_into
from ..models import monitored_errors, steady_invariants

# ---- status codes: the driver never raises; a run ends with one of these ----
OK = 0
STEP_BUDGET = 1
STEP_UNDERFLOW = 2
NON_FINITE = 3
LENGTH_ERROR = 4
STEADY = 5  # success: stopped early in a steady terminal state
REFINE = 6  # not an end: the state outgrew its resolution; go on at a higher one
SUCCESS = (OK, STEADY)
STATUS_NAMES = {
    OK: "ok",
    STEP_BUDGET: "step budget exhausted",
    STEP_UNDERFLOW: "step size underflow",
    NON_FINITE: "non-finite state",
    LENGTH_ERROR: "length error too large",
    STEADY: "ok",
    REFINE: "truncation outgrown (resolution_tol passed)",
}
#: Why a run stopped, per status.
STOP_REASONS = {**STATUS_NAMES, OK: "t_end", STEADY: "steady"}

# ---- step-size controller (the constants of scipy.integrate.RK45) ----------
SAFETY = 0.9
MIN_FACTOR = 0.2
MAX_FACTOR = 10.0
#: Relative stretch of a step allowed rather than leave a sliver before an output time.
LANDING_STRETCH = 1e-8
#: Consecutive quiet check intervals that make a steady state.
STEADY_WINDOWS = 2
#: Machine epsilon of float64, a constant for kernels (``np.finfo`` inside a kernel costs
#: compile time).
EPS = float(np.finfo(np.float64).eps)

StepOptions = collections.namedtuple(
    "StepOptions",
    "rtol atol first_step min_step max_step max_steps constraint_tol steady_interval steady_tol"
    " resolution_tol",
)


def step_options(rtol, atol, first_step=None, min_step=0.0, max_step=np.inf,
                 max_steps=1_000_000, constraint_tol=np.inf, steady_interval=0.0,
                 steady_tol=0.0, resolution_tol=np.inf):
    """Driver options (scipy names where they exist) as a ``StepOptions`` tuple.

    first_step: None selects the starting step automatically.
    constraint_tol: stop with LENGTH_ERROR once |constraint_error| exceeds it.
    steady_interval, steady_tol: at the first accepted step at least
    ``steady_interval`` after the previous check, compare the model's
    invariants (``models.steady_invariants``) with their values there; when
    no invariant changed by more than ``steady_tol`` per ``steady_interval``
    (the change is scaled by steady_interval / elapsed time, so long implicit
    steps are judged like short ones) at STEADY_WINDOWS consecutive checks,
    stop with status STEADY.  steady_interval <= 0 disables the check.
    resolution_tol: stop with REFINE once the model's ``resolution_error`` (for a loop:
    the spectral tail) exceeds it after an accepted step (``refinement`` then goes on
    at a higher truncation).
    """
    return StepOptions(float(rtol), float(atol), -1.0 if first_step is None else float(first_step),
                       float(min_step), float(max_step), int(max_steps), float(constraint_tol),
                       float(steady_interval), float(steady_tol), float(resolution_tol))


@kernel
def rms_norm(v, scale):
    """sqrt(mean((v_i / scale_i)²))."""
    acc = 0.0
    for i in range(v.shape[0]):
        acc += (v[i] / scale[i]) ** 2
    return np.sqrt(acc / v.shape[0])


@kernel
def error_scale(y, y_new, rtol, atol, scale):
    """scale_i = atol + rtol max(|y_i|, |y_new_i|), written into ``scale``."""
    for i in range(y.shape[0]):
        scale[i] = atol + rtol * max(abs(y[i]), abs(y_new[i]))


@kernel
def step_factor(err_norm, error_order):
    """Step-size factor SAFETY err^(-1/(p+1)), clipped to [MIN_FACTOR, MAX_FACTOR]."""
    if err_norm == 0.0:
        return MAX_FACTOR
    if not np.isfinite(err_norm):
        return MIN_FACTOR
    return min(MAX_FACTOR, max(MIN_FACTOR, SAFETY * err_norm ** (-1.0 / (error_order + 1))))


@kernel
def all_finite(a):
    for v in a.flat:
        if not np.isfinite(v):
            return False
    return True


@kernel
def max_abs_difference(a, b):
    worst = 0.0
    for i in range(a.shape[0]):
        worst = max(worst, abs(a[i] - b[i]))
    return worst


@kernel
def initial_step_probe(y0, f0, rtol, atol, y1):
    """First half of the Hairer–Nørsett–Wanner starting step (as scipy's): with
    ‖v‖ = rms(v_i / (atol + rtol |y0_i|)), h0 = 0.01 ‖y0‖ / ‖f0‖ (1e-6 if either norm is
    below 1e-5) and y1 = y0 + h0 f0 (written).  Returns (h0, ‖f0‖); the caller evaluates
    F(y1) for :func:`initial_step`."""
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
    for i in range(ny):
        y1[i] = y0[i] + h0 * f0[i]
    return h0, d1


@kernel
def initial_step(y0, f0, f1, h0, f0_norm, rtol, atol, error_order, h_max):
    """Second half of the starting step (:func:`initial_step_probe` gave h0 and ‖f0‖;
    f1 = F(y0 + h0 f0)): with d2 = ‖f1 − f0‖ / h0, h1 = (0.01 / max(‖f0‖, d2))^(1/(p+1))
    (max(1e-6, 1e-3 h0) if both are below 1e-15); returns min(100 h0, h1, h_max).

    The right-hand side is the caller's to evaluate: this kernel holds no model code.
    """
    ny = y0.shape[0]
    d2 = 0.0
    for i in range(ny):
        scale = atol + rtol * abs(y0[i])
        d2 += ((f1[i] - f0[i]) / scale) ** 2
    d2 = np.sqrt(d2 / ny) / h0
    if f0_norm <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(f0_norm, d2)) ** (1.0 / (error_order + 1))
    return min(100.0 * h0, h1, h_max)


# ---- output times and monitors ----------------------------------------------
@kernel
def outputs_at_start(y, t0, t_out, y_out):
    """y_out[i] = y for the output times t_out[i] <= t0; returns the next output's index."""
    i_out = 0
    while i_out < t_out.shape[0] and t_out[i_out] <= t0:
        copy_into(y_out[i_out], y)
        i_out += 1
    return i_out


@kernel
def monitor_start(problem, y, t0, options):
    """The steady-state monitor's start: (next_check, invariants, quiet)."""
    return t0 + options.steady_interval, steady_invariants(problem, y), np.int64(0)


@kernel
def initial_worst(problem, y):
    """The monitors' record at the start (see :func:`monitor`): no constraint error yet
    (the start's is the user's), no resolution error counted yet, the start's
    resolution size as the previous one, not rising."""
    worst = np.zeros(4)
    worst[2] = monitored_errors(problem, y)[2]
    return worst


@kernel
def landing(t, h, t_end):
    """Step to try from t: h, shortened to land exactly on t_end (or stretched by up to
    LANDING_STRETCH rather than leave a sliver).  Output times are not landed on: they
    come from the methods' dense output, so asking for output never changes the steps.

    Returns (h_try, clipped).
    """
    if t + h * (1.0 + LANDING_STRETCH) >= t_end:
        return t_end - t, True
    return h, False


@kernel
def monitor(problem, t, y, t_end, options, worst, next_check, previous, quiet):
    """After an accepted step: constraint error, resolution and steady state.

    ``worst`` (updated in place) = [largest |constraint error|, largest resolution
    error once rising, the previous resolution size, rising (0 or 1)].  REFINE
    comes as soon as the resolution error passes ``options.resolution_tol``; the
    *record* counts it only from the first accepted step at which its absolute size
    (``models.monitored_errors``) grew, since the decay of a start's own seeded high
    modes is the initial condition, not dynamics that outgrew the truncation.  Returns (status or -1 to go on,
    next_check, previous, quiet).
    """
    constraint, resolution, size = monitored_errors(problem, y)
    worst[0] = max(worst[0], abs(constraint))
    if worst[0] > options.constraint_tol:
        return LENGTH_ERROR, next_check, previous, quiet
    if size > worst[2]:
        worst[3] = 1.0
    worst[2] = size
    if worst[3] > 0.0:
        worst[1] = max(worst[1], resolution)
    if resolution > options.resolution_tol:
        return REFINE, next_check, previous, quiet
    if options.steady_interval > 0.0 and t >= next_check and t < t_end:
        current = steady_invariants(problem, y)
        # change per steady_interval, whatever the steps' length since the last check
        elapsed = t - (next_check - options.steady_interval)
        change = max_abs_difference(current, previous) * options.steady_interval / elapsed
        quiet = quiet + 1 if change <= options.steady_tol else 0
        if quiet >= STEADY_WINDOWS:
            return STEADY, next_check, current, quiet
        previous = current
        next_check = t + options.steady_interval
    return -1, next_check, previous, quiet


@kernel
def stop_check(options, n_steps, h, t, y):
    """Status that ends the run before the next attempt, or -1."""
    if n_steps >= options.max_steps:
        return STEP_BUDGET
    if h < max(options.min_step, 10.0 * EPS * abs(t)):
        return STEP_UNDERFLOW if all_finite(y) else NON_FINITE
    return -1
