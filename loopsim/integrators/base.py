"""The integrator interface: the three method-specific pieces the driver calls.

A *method* is a namedtuple type (its coefficients and policy constants, with
an ``error_order`` field) plus njit implementations of these generic
functions, registered with ``@implements(generic, MethodType)``
(``loopsim.dispatch``).  The driver (``integrators.driver``) owns everything
else: output times, step budget, monitors, statuses.
"""
from ..dispatch import generic, implements  # noqa: F401 - implements is re-exported


@generic
def start(method, problem, y, f, options):
    """Workspace of the method for state size y.size, after any start-up work at y
    (f = F(y)); returns (workspace, RHS evaluations spent)."""
    raise NotImplementedError("only callable from jitted code")


#: The step size that asks ``attempt`` for no step: only the work ``start`` or ``advance``
#: left to be done at their (y, f).  The driver calls ``attempt(..., CATCH_UP, ...)``
#: right after each of them, so the work is done where it was asked for; radau5 leaves
#: its Jacobian evaluations to it, so that besides the driver one compiled function (the
#: attempt) holds the Jacobian's code, not three (docs/studies/performance.md, "Compilation").
#: A real step has h > 0 (``control.stop_check`` ends the run first).
CATCH_UP = -1.0


@generic
def attempt(method, work, problem, y, f, h, y_new, options):
    """Attempt one step of size h from y (f = F(y)): y_new and the verdict.

    Returns (accepted, h_next, RHS evaluations): h_next is the step to retry
    with after a rejection, or the proposal after an acceptance.  With h =
    :data:`CATCH_UP` there is no step: the work start or advance left at (y, f) is done
    (nothing for most methods), and it returns (True, 0.0, RHS evaluations).
    """
    raise NotImplementedError("only callable from jitted code")


@generic
def advance(method, work, problem, y, f, h, h_proposal):
    """Bookkeeping after an accepted step of size h that ended at y (f = F(y)):
    returns (next step size, RHS evaluations spent)."""
    raise NotImplementedError("only callable from jitted code")


@generic
def dense_output(method, work, problem, y_old, f_old, y, f, h, theta, out, options):
    """out = the state at t_old + theta h (0 < theta < 1) within the accepted step from
    y_old (f_old = F(y_old)) to y (f = F(y)), by the method's dense output (``options``:
    the run's step options); returns the RHS evaluations it cost.  It must not change
    what the next step does."""
    raise NotImplementedError("only callable from jitted code")


@generic
def statistics(method, work):
    """(Jacobian evaluations, LU factorisations) made so far by the method."""
    raise NotImplementedError("only callable from jitted code")
