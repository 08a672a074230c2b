"""Right-hand sides the integrators can advance, specialised by problem type.

A problem is a namedtuple; :func:`rhs` and :func:`constraint_error` are
resolved on its type when the calling driver is compiled (``numba.extending.
overload``), so the drivers stay generic and every specialisation is cached.

* :class:`LoopProblem`: the sedimenting loop, state y = x.ravel() with x the
  (3, 2n+1) position coefficients (``spectral`` layout); dy/dt = u.
Each problem type also provides its exact Jacobian (:func:`jacobian`), used
by the implicit integrator.

* :class:`RiccatiProblem`: y_i' = a_i y_i², exact solution
  y_i(t) = y_i(0) / (1 - a_i y_i(0) t); a nonlinear closed form used to
  verify the order of the integrators.
"""
import collections

import numpy as np
from numba import types
from numba.extending import overload

from . import physics
from .config import JIT

LoopProblem = collections.namedtuple("LoopProblem", "g0 w ops ws")
RiccatiProblem = collections.namedtuple("RiccatiProblem", "rates")


def make_loop_problem(n, g0, w, ops=None):
    """Loop problem at truncation n (operators shared when given)."""
    ops = physics.make_operators(n) if ops is None else ops
    return LoopProblem(float(g0), float(w), ops, physics.make_workspace(n))


def rhs(problem, y, dydt):
    """dydt = F(y) for the problem (compiled per problem type)."""
    raise NotImplementedError("only callable from jitted code")


def constraint_error(problem, y):
    """The invariant the driver monitors (relative length error for a loop)."""
    raise NotImplementedError("only callable from jitted code")


def jacobian(problem, y, f, jac, work_y, work_f):
    """jac = ∂F/∂y at y (f = F(y) given); returns the RHS evaluations it cost."""
    raise NotImplementedError("only callable from jitted code")


def steady_invariants(problem, y):
    """Quantities whose standstill defines a steady (terminal) state."""
    raise NotImplementedError("only callable from jitted code")


def _is(problem_type, cls):
    return isinstance(problem_type, types.BaseNamedTuple) and problem_type.instance_class is cls


@overload(rhs, jit_options=JIT)
def _rhs(problem, y, dydt):
    if _is(problem, LoopProblem):
        def loop_rhs(problem, y, dydt):
            k = y.shape[0] // 3
            physics.loop_velocity(
                y.reshape((3, k)), problem.g0, problem.w, problem.ops, problem.ws,
                dydt.reshape((3, k)),
            )
        return loop_rhs
    if _is(problem, RiccatiProblem):
        def riccati_rhs(problem, y, dydt):
            for i in range(y.shape[0]):
                dydt[i] = problem.rates[i] * y[i] * y[i]
        return riccati_rhs


@overload(constraint_error, jit_options=JIT)
def _constraint_error(problem, y):
    if _is(problem, LoopProblem):
        def loop_length_error(problem, y):
            k = y.shape[0] // 3
            return physics.relative_length_error(y.reshape((3, k)), problem.ops, problem.ws)
        return loop_length_error
    if _is(problem, RiccatiProblem):
        def no_constraint(problem, y):
            return 0.0
        return no_constraint


@overload(steady_invariants, jit_options=JIT)
def _steady_invariants(problem, y):
    if _is(problem, LoopProblem):
        def loop_invariants(problem, y):
            # covariance eigenvalues (size and shape; invariant under rigid motions and
            # arc-length shifts) and |n_z| of the best-fit plane's normal (the tilt)
            k = y.shape[0] // 3
            x = y.reshape((3, k))
            cov = np.zeros((3, 3))
            for a in range(3):
                for b in range(3):
                    acc = 0.0
                    for j in range(1, k):
                        acc += x[a, j] * x[b, j]
                    cov[a, b] = 0.5 * acc
            values, vectors = np.linalg.eigh(cov)
            out = np.empty(4)
            out[:3] = values
            out[3] = abs(vectors[2, 0])
            return out
        return loop_invariants
    if _is(problem, RiccatiProblem):
        def riccati_invariants(problem, y):
            return y.copy()
        return riccati_invariants


@overload(jacobian, jit_options=JIT)
def _jacobian(problem, y, f, jac, work_y, work_f):
    if _is(problem, LoopProblem):
        def loop_jacobian(problem, y, f, jac, work_y, work_f):
            k = y.shape[0] // 3
            physics.loop_jacobian(y.reshape((3, k)), problem.g0, problem.w, problem.ops,
                                  problem.ws, jac)
            return 1  # one velocity evaluation inside
        return loop_jacobian
    if _is(problem, RiccatiProblem):
        def riccati_jacobian(problem, y, f, jac, work_y, work_f):
            jac[:] = 0.0
            for i in range(y.shape[0]):
                jac[i, i] = 2.0 * problem.rates[i] * y[i]
            return 0
        return riccati_jacobian
