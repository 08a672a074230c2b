"""Nonlocal slender-body theory: the loop of ``local_sbt`` with the full SBT mobility,
problem type :class:`NonlocalProblem` (docs/nonlocal.md).

The same state, force, penalty and least-squares tension as the local model; the
velocity u = (1/c)(Λ + K)[f] (c = −2 log ε, ε = a/L) on the local model's 4n + 1 grid
(``nonlocal_maps.nonlocal_loop_velocity``), which tends to the local model as c → ∞.
The Jacobian is exact (``nonlocal_maps.nonlocal_jacobian``).  Chosen with
``model="nonlocal"`` and ``slenderness=ε`` (``models.Model``) in ``simulate``, sweeps and
the command line.
"""
import collections

import numpy as np

from . import local_sbt
from .base import (
    auxiliary, for_case, implements, jacobian, monitored_errors, rhs, steady_invariants,
)
from .loop_maps import LoopOperators, make_operators, make_workspace
from .nonlocal_maps import nonlocal_jacobian, nonlocal_loop_velocity
from .nonlocal_operator import singular_weights, slenderness_constant  # noqa: F401 - re-exported

#: The problem: g0, w and c = −2 log ε; the local model's operators and workspace; the
#: nonlocal rule's weights q on the grid and its scratch (grid positions, W, e).
NonlocalProblem = collections.namedtuple(
    "NonlocalProblem", "g0 w c singular ops ws position weight direction")
#: Order of the per-case parameters passed to ``for_case``: c = −2 log ε, not ε.
PARAMETERS = ("g0", "w", "c")
#: What the cases of one truncation share: the local operators' fields, then the nonlocal
#: rule's weights (flat: Numba's parallel kernels take no nested tuples).
NonlocalConstants = collections.namedtuple(
    "NonlocalConstants", LoopOperators._fields + ("singular",))
_OPERATOR_FIELDS = len(LoopOperators._fields)


def make_problem(n, g0, w, eps, ops=None):
    """Nonlocal loop problem at truncation n and slenderness ε = a/L (operators shared
    when given)."""
    ops = make_operators(n) if ops is None else ops
    m = ops.m
    return NonlocalProblem(float(g0), float(w), slenderness_constant(eps), singular_weights(m),
                           ops, make_workspace(n), np.empty((3, m)), np.empty((m, m)),
                           np.empty((3, m, m)))


def constants(problem):
    """What every case of one truncation shares: the operators and the singular weights."""
    return NonlocalConstants(*problem.ops, problem.singular)


def shared_constants(n):
    """:func:`constants` of truncation n."""
    ops = make_operators(n)
    return NonlocalConstants(*ops, singular_weights(ops.m))


@implements(for_case, NonlocalConstants)
def _nonlocal_for_case(constants, parameters):
    ops = LoopOperators(*constants[:_OPERATOR_FIELDS])
    m = ops.m
    return NonlocalProblem(parameters[0], parameters[1], parameters[2], constants.singular,
                           ops, make_workspace(ops.n), np.empty((3, m)), np.empty((m, m)),
                           np.empty((3, m, m)))


@implements(rhs, NonlocalProblem)
def _nonlocal_rhs(problem, y, dydt):
    k = y.shape[0] // 3
    nonlocal_loop_velocity(y.reshape((3, k)), problem.g0, problem.w, problem.c,
                           problem.singular, problem.ops, problem.ws, problem.position,
                           problem.weight, problem.direction, dydt.reshape((3, k)))


@implements(jacobian, NonlocalProblem)
def _nonlocal_jacobian(problem, y, f, jac, work_y, work_f):
    """The exact Jacobian (``nonlocal_maps.nonlocal_jacobian``); one velocity inside."""
    k = y.shape[0] // 3
    nonlocal_jacobian(y.reshape((3, k)), problem.g0, problem.w, problem.c, problem.singular,
                      problem.ops, problem.ws, problem.position, problem.weight,
                      problem.direction, jac)
    return 1


for _generic, _implementation in ((monitored_errors, local_sbt.loop_errors),
                                   (steady_invariants, local_sbt.loop_invariants),
                                   (auxiliary, local_sbt.loop_multiplier)):
    implements(_generic, NonlocalProblem)(_implementation)  # the local model's: same fields
