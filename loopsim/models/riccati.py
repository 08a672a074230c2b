"""A closed-form test model for the integrators: y_i' = a_i y_i².

Exact solution y_i(t) = y_i(0) / (1 - a_i y_i(0) t): nonlinear, with a
blow-up at t = 1 / (a_i y_i(0)), so it checks orders, tolerances and failure
statuses of every registered integrator.
"""
import collections

from .base import (
    auxiliary, for_case, implements, jacobian, monitored_errors, rhs, steady_invariants,
)

RiccatiProblem = collections.namedtuple("RiccatiProblem", "rates")
PARAMETERS = ()


def exact_solution(rates, y0, t):
    """y(t) = y0 / (1 - a y0 t)."""
    return y0 / (1.0 - rates * y0 * t)


@implements(rhs, RiccatiProblem)
def _riccati_rhs(problem, y, dydt):
    for i in range(y.shape[0]):
        dydt[i] = problem.rates[i] * y[i] * y[i]


@implements(jacobian, RiccatiProblem)
def _riccati_jacobian(problem, y, f, jac, work_y, work_f):
    jac[:] = 0.0
    for i in range(y.shape[0]):
        jac[i, i] = 2.0 * problem.rates[i] * y[i]
    return 0


@implements(monitored_errors, RiccatiProblem)
def _no_constraint_no_truncation(problem, y):
    return 0.0, 0.0, 0.0


@implements(steady_invariants, RiccatiProblem)
def _riccati_invariants(problem, y):
    return y.copy()


@implements(auxiliary, RiccatiProblem)
def _no_auxiliary(problem, out):
    pass


def constants(problem):
    """What every case shares: the whole (parameter-free) problem."""
    return problem


@implements(for_case, RiccatiProblem)
def _riccati_for_case(problem, parameters):
    return RiccatiProblem(problem.rates.copy())
