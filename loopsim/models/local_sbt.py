"""Local slender-body theory: the loop model of the paper (§5), problem type :class:`LoopProblem`.

The first model of ``loopsim.models``: the interface of ``models.base`` implemented for a
closed inextensible Euler–Bernoulli loop in local slender-body theory.  Its kernels:
``loop_maps`` (the velocity: the three affine maps and the least-squares tension),
``loop_jacobian`` (the velocity's exact Jacobian) and ``loop_shape`` (length error, spectral
tail and steady-state invariants).  Their names are re-exported here.
"""
import collections

import numpy as np

from ..linalg import copy_into
from .base import (
    auxiliary, for_case, implements, jacobian, monitored_errors, rhs, steady_invariants,
)
from .loop_jacobian import loop_jacobian, mobility_jacobian  # noqa: F401 - re-exported
from .loop_maps import (  # noqa: F401 - re-exported
    LoopOperators, Workspace, compose_maps, force_map, grid_size, length_creation,
    length_creation_map, length_rate_operator, loop_velocity, loop_velocity_blocks,
    make_operators, make_workspace, shape_on_grid, tension_columns, tension_operator,
    velocity_map,
)
from .loop_shape import (  # noqa: F401 - re-exported
    energy_sums, relative_length_error, shape_invariants, spectral_tail, top_mode_share,
)


# ---- the model interface (models.base) --------------------------------------
#: The problem: parameters g0 (gravity over stiffness) and w (length-penalty rate),
#: the operators of one truncation order (shared) and a per-case workspace.
#: State y = x.ravel(), x the (3, 2n+1) position coefficients; dy/dt = u.
LoopProblem = collections.namedtuple("LoopProblem", "g0 w ops ws")
#: Order of the per-case parameters passed to ``for_case``.
PARAMETERS = ("g0", "w")


def make_problem(n, g0, w, ops=None):
    """Loop problem at truncation n (operators shared when given)."""
    ops = make_operators(n) if ops is None else ops
    return LoopProblem(float(g0), float(w), ops, make_workspace(n))


# The velocity is the right-hand side itself: one compiled function, not an adapter
# calling a kernel (loop_maps.loop_velocity).
implements(rhs, LoopProblem)(loop_velocity)


@implements(jacobian, LoopProblem)
def _loop_jacobian(problem, y, f, jac, work_y, work_f):
    # loop_jacobian's two calls, not a call of that kernel: every library holding the
    # Jacobian holds all its callees' code, so a layer fewer compiles it once less
    # (docs/studies/performance.md, "Compilation").
    k = y.shape[0] // 3
    x = y.reshape((3, k))
    u = np.empty_like(x)
    loop_velocity_blocks(x, problem.g0, problem.w, problem.ops, problem.ws, u)
    mobility_jacobian(problem.w, 1.0, 1.0, 0.0, None, None, None, problem.ops, problem.ws, jac)
    return 1  # one velocity evaluation inside


# The monitors and the multiplier read only the shape and the fields ops and ws: every
# model of this loop (``nonlocal_sbt`` too) registers these same implementations.
@implements(monitored_errors, LoopProblem)
def loop_errors(problem, y):
    """(relative length error, spectral tail, top-mode share) of the loop y."""
    x = y.reshape((3, y.shape[0] // 3))
    return (relative_length_error(x, problem.ops, problem.ws), spectral_tail(x),
            top_mode_share(x))


@implements(steady_invariants, LoopProblem)
def loop_invariants(problem, y):
    """The shape invariants of the loop y (``loop_shape.shape_invariants``)."""
    return shape_invariants(y.reshape((3, y.shape[0] // 3)))


@implements(auxiliary, LoopProblem)
def loop_multiplier(problem, out):
    """The tension multiplier of the last right-hand side (problem.ws.tension)."""
    copy_into(out, problem.ws.tension)


def constants(problem):
    """What every case of one truncation shares: the operators."""
    return problem.ops


@implements(for_case, LoopOperators)
def _loop_for_case(ops, parameters):
    return LoopProblem(parameters[0], parameters[1], ops, make_workspace(ops.n))
