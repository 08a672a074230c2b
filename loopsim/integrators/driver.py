"""One adaptive driver for every method: the loop around a method's step attempts.

The driver owns what no method should repeat: the first right-hand side
and step size, output at requested times (from the method's dense output:
steps never land on output times, so asking for output leaves the
trajectory bit-for-bit unchanged), the step budget and underflow, the
model's constraint and steady-state monitors, and the status.  It never
raises: failures come back as a status code (``integrators.control``).  The
method-specific pieces (``start``, ``attempt``, ``advance``, ``dense_output``,
``statistics``; see ``integrators.base``) are resolved on the method's type
when the driver is compiled.
"""
import numpy as np

from ..jit import entry, kernel
from ..linalg import copy_into
from ..models import rhs
from .base import CATCH_UP, advance, attempt, dense_output, start, statistics
from .control import (
    NON_FINITE, OK, all_finite, initial_step, initial_step_probe, initial_worst, landing, monitor,
    monitor_start, outputs_at_start, stop_check,
)


#: The run statistics returned by :func:`integrate`, in order (solve_ivp's names where
#: they exist).
COUNTS = ("steps_accepted", "steps_rejected", "nfev", "njev", "nlu")


@kernel
def _counts(method, work, counts, n_acc, n_rej, n_rhs):
    njev, nlu = statistics(method, work)
    counts[0] = n_acc
    counts[1] = n_rej
    counts[2] = n_rhs
    counts[3] = njev
    counts[4] = nlu
    return counts


@entry
def integrate(method, problem, y0, t0, t_end, t_out, options, y_out):
    """Integrate dy/dt = rhs(problem, y) from t0 to t_end with ``method`` and ``options``
    (``control.step_options``).

    t_out: sorted output times in [t0, t_end]; the state at t_out[i] is written
    to y_out[i] (exactly at t0 and t_end, by the method's dense output between
    steps).  Rows of y_out for times not reached are left untouched.  t_out = y_out =
    None: no output (the end state is returned), and Numba compiles this call without
    the output code, dense output included.  Runs, their twins and sweeps all pass arrays
    (empty ones for no output: the same steps and counts), so that a command compiles
    one specialisation of this driver, which holds all the method's and model's code.

    Returns (status, t, y, counts, worst): counts (int64) = [accepted steps,
    rejected steps, RHS evaluations of the steps (dense output's are not counted), Jacobian
    evaluations, LU factorisations]
    (``COUNTS``); worst[:2] = [largest |constraint_error| at the accepted steps,
    largest resolution_error at the accepted steps once it has started to grow]
    (``control.monitor``; worst[2:] is the monitor's state) (for a loop: the worst transient relative length
    error and spectral tail).  Status REFINE (``options.resolution_tol`` exceeded) ends
    the run at the step that outgrew the truncation.

    Longer than a screen: a Numba entry whose loop is the one adaptive loop of every
    method (start, attempt, accept or reject, output, monitors); its steps are already
    the method's generics, and what is left is their order, read best in one place.
    """
    counts = np.zeros(len(COUNTS), dtype=np.int64)
    ny = y0.shape[0]
    y = y0.copy()
    f = np.empty(ny)
    y_new = np.empty(ny)
    y_old = np.empty(ny)
    f_old = np.empty(ny)
    n_acc = np.int64(0)  # not the literal 0: one specialisation of the callees
    n_rej = np.int64(0)
    t = t0
    worst = initial_worst(problem, y)
    rhs(problem, y, f)
    n_rhs = 1
    if not all_finite(f) or not all_finite(y):
        counts[2] = n_rhs
        return NON_FINITE, t, y, counts, worst
    i_out = 0
    if t_out is not None:  # decided at compile time (Numba prunes the branch on None)
        i_out = outputs_at_start(y, t0, t_out, y_out)
    next_check, previous, quiet = monitor_start(problem, y, t0, options)
    work, evals = start(method, problem, y, f, options)
    n_rhs += evals + attempt(method, work, problem, y, f, CATCH_UP, y_new, options)[2]
    if options.first_step > 0.0:
        h = min(options.first_step, options.max_step)
    else:
        h0, f_norm = initial_step_probe(y, f, options.rtol, options.atol, y_old)
        rhs(problem, y_old, y_new)
        n_rhs += 1
        h = initial_step(y, f, y_new, h0, f_norm, options.rtol, options.atol,
                         method.error_order, options.max_step)
    while t < t_end:
        stop = stop_check(options, n_acc + n_rej, h, t, y)
        if stop >= 0:
            return stop, t, y, _counts(method, work, counts, n_acc, n_rej, n_rhs), worst
        h_try, clipped = landing(t, h, t_end)
        accepted, h_next, evals = attempt(method, work, problem, y, f, h_try, y_new, options)
        n_rhs += evals
        if not accepted:
            n_rej += 1
            h = h_next
            continue
        n_acc += 1
        t_old = t
        t = t_end if clipped else t + h_try
        copy_into(y_old, y)
        copy_into(f_old, f)
        copy_into(y, y_new)
        rhs(problem, y, f)
        n_rhs += 1
        if not all_finite(f):
            return NON_FINITE, t, y, _counts(method, work, counts, n_acc, n_rej, n_rhs), worst
        if t_out is not None:
            while i_out < t_out.shape[0] and t_out[i_out] <= t:
                if t_out[i_out] == t:
                    copy_into(y_out[i_out], y)
                else:  # its evaluations are output's, not the step's: not in nfev, so
                    # asking for output changes no count (a sweep's traced rows equal
                    # the others)
                    dense_output(method, work, problem, y_old, f_old, y, f, h_try,
                                 (t_out[i_out] - t_old) / h_try, y_out[i_out], options)
                i_out += 1
        stop, next_check, previous, quiet = monitor(
            problem, t, y, t_end, options, worst, next_check, previous, quiet)
        if stop >= 0:
            return stop, t, y, _counts(method, work, counts, n_acc, n_rej, n_rhs), worst
        h_next, evals = advance(method, work, problem, y, f, h_try, h_next)
        n_rhs += evals + attempt(method, work, problem, y, f, CATCH_UP, y_new, options)[2]
        h = min(options.max_step, h_next)
    return OK, t, y, _counts(method, work, counts, n_acc, n_rej, n_rhs), worst
