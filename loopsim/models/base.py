"""The model interface: what integrators, the batch kernel and the API ask of a model.

A *model* is a namedtuple type holding its parameters, its constant operators
and a per-case workspace (so the right-hand side never allocates), plus njit
implementations of the generic functions below, registered for that type
with ``@implements(generic, ProblemType)`` (``loopsim.dispatch``).  The state
y is always a flat float64 vector.  Each model module also provides
``make_problem(...)``, ``PARAMETERS`` (the order of the per-case parameters
that :func:`for_case` takes) and ``constants(problem)`` (what cases share).
"""
from ..dispatch import generic, implements  # noqa: F401 - implements is re-exported


@generic
def rhs(problem, y, dydt):
    """dydt = F(y)."""
    raise NotImplementedError("only callable from jitted code")


@generic
def jacobian(problem, y, f, jac, work_y, work_f):
    """jac = ∂F/∂y at y (f = F(y) given; work_y, work_f scratch); returns the RHS
    evaluations it cost."""
    raise NotImplementedError("only callable from jitted code")


@generic
def monitored_errors(problem, y):
    """What the driver monitors after each accepted step, as (constraint_error,
    resolution_error, resolution_size):

    * constraint_error: the invariant's error (for a loop: the relative length error);
    * resolution_error: how close the state is to the model's resolution limit (for a
      loop: the spectral tail, the share of its deformation in its top two Fourier
      modes); 0 for a model without a truncation;
    * resolution_size: the absolute size of what resolution_error measures (for a loop:
      the top modes' RMS amplitude relative to the loop's size): while it shrinks, the
      top modes are the start's own, decaying, and the driver does not count the error;
      0 for a model without a truncation.

    One generic for the three: each implementation taking the problem is a compiled
    library of its own (docs/studies/performance.md, "Compilation")."""
    raise NotImplementedError("only callable from jitted code")


@generic
def steady_invariants(problem, y):
    """Quantities (1-D array) whose standstill defines a steady terminal state."""
    raise NotImplementedError("only callable from jitted code")


@generic
def auxiliary(problem, out):
    """Copy into ``out`` the model's auxiliary field from the last :func:`rhs` call
    (for a loop: the tension multiplier)."""
    raise NotImplementedError("only callable from jitted code")


@generic
def for_case(constants, parameters):
    """A problem of one case: the model's shared ``constants`` (its operators: a flat
    namedtuple, since Numba's parallel kernels take no nested tuples), its own workspace
    and the per-case ``parameters`` (1-D float array in the model's ``PARAMETERS`` order).
    Dispatched on the type of ``constants``."""
    raise NotImplementedError("only callable from jitted code")
