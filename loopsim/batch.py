"""Many trajectories of one truncation order in one parallel Numba kernel.

Each case b integrates its own initial shape with its own workspace and
writes only row b of the outputs, so the result does not depend on the
number of threads or on the order in which threads take the cases.
Load balance: 3D cases cost several times more than stable ones, and
Numba's ``parallel_chunksize`` did not change the schedule of this kernel
under the OpenMP layer (measured: no effect on a loop of uneven items), so
:func:`integrate_cases` balances by hand.  Cases are dealt round-robin, in
order of decreasing estimated cost, onto one lane per thread; the prange
runs over the lanes.
"""
import numba
import numpy as np

from . import physics
from .config import JIT
from .integrate import integrate
from .problems import LoopProblem

_PARALLEL_JIT = dict(JIT, parallel=True)


@numba.njit(**_PARALLEL_JIT)
def _integrate_cases(method, ops, g0, w, x0, t_end, options, order, lanes, y_final, t_final,
                     status, counts, worst_length):
    no_output_times = np.empty(0)
    no_output_rows = np.empty((0, x0.shape[1]))  # read-only: no output times, nothing written
    for lane in numba.prange(lanes):
        for position in range(lane, order.shape[0], lanes):
            b = order[position]  # case b writes only row b of the outputs
            problem = LoopProblem(g0[b], w[b], ops, physics.make_workspace(ops.n))
            result = integrate(method, problem, x0[b], 0.0, t_end[b], no_output_times, options,
                               no_output_rows)
            status[b] = result[0]
            t_final[b] = result[1]
            y_final[b] = result[2]
            counts[b, 0] = result[3]
            counts[b, 1] = result[4]
            counts[b, 2] = result[5]
            worst_length[b] = result[6]


def integrate_cases(method, ops, g0, w, x0, t_end, options, cost=None, lanes=None):
    """Integrate B cases (g0, w, t_end: arrays of length B or scalars; x0 of shape
    (B, 3(2n+1))) in parallel with the driver ``options`` (``integrate.step_options``).

    Returns (y_final, t_final, status, counts, worst_length): counts[:, 0:3] =
    accepted steps, rejected steps, RHS evaluations; worst_length the largest
    relative length error met along each trajectory.  ``cost``: an estimate
    of each case's cost (any monotone proxy; default: all equal) used to deal
    cases onto ``lanes`` (default: the Numba thread count).
    """
    cases = x0.shape[0]
    y_final = np.full_like(x0, np.nan)
    t_final = np.zeros(cases)
    status = np.zeros(cases, dtype=np.int64)
    counts = np.zeros((cases, 3), dtype=np.int64)
    worst_length = np.zeros(cases)
    as_array = lambda v: np.ascontiguousarray(np.broadcast_to(np.asarray(v, float), (cases,)))
    order = np.arange(cases) if cost is None else np.argsort(-np.asarray(cost, float), kind="stable")
    lanes = numba.get_num_threads() if lanes is None else int(lanes)
    _integrate_cases(method, ops, as_array(g0), as_array(w), np.ascontiguousarray(x0),
                     as_array(t_end), options, order, lanes, y_final, t_final, status, counts,
                     worst_length)
    return y_final, t_final, status, counts, worst_length
