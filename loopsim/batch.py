"""Many trajectories of one truncation order in one parallel Numba kernel.

Each case b integrates its own initial shape with its own workspace and
writes only row b of the outputs, so the result does not depend on the
number of threads or on the order in which threads take the cases.
Load balance: 3D cases cost several times more than stable ones, and
Numba's ``parallel_chunksize`` did not change the schedule of this kernel
under the OpenMP layer (measured: no effect on a loop of uneven items), so
:func:`integrate_batch` balances by hand.  Cases are dealt round-robin, in
order of decreasing estimated cost, onto one lane per thread; the prange
runs over the lanes.
"""
import typing

import numba
import numpy as np

from .integrators import COUNTS, integrate
from .jit import JIT, entry
from .models import for_case

_PARALLEL_JIT = dict(JIT, parallel=True)


@entry  # called from Python by the serial path
def case_problem(constants, parameters):
    """The problem of one case (``models.for_case``)."""
    return for_case(constants, parameters)


@numba.njit(**_PARALLEL_JIT)
def parallel_cases(method, constants, parameters, x0, t0, t_end, t_samples, options, order, lanes,
                   y_final, t_final, status, counts, worst, samples):
    """One lane per thread (``numba.prange``): lane l integrates the cases order[l],
    order[l + lanes], ...; case b writes only row b (and samples[b], its states at the
    times t_samples[b]).  The lane's loop is the prange body itself: no separate lane
    kernel compiles the model's code once more."""
    for lane in numba.prange(lanes):
        for position in range(lane, order.shape[0], lanes):
            b = order[position]
            problem = for_case(constants, parameters[b])
            result = integrate(method, problem, x0[b], t0[b], t_end[b], t_samples[b], options,
                               samples[b])
            status[b] = result[0]
            t_final[b] = result[1]
            y_final[b] = result[2]
            counts[b] = result[3]
            worst[b] = result[4][:2]


class BatchRun(typing.NamedTuple):
    """What :func:`integrate_batch` returns, per case b (a tuple: it unpacks in this order)."""

    y_final: np.ndarray  #: (B, ny) terminal states
    t_final: np.ndarray  #: (B,) time reached
    status: np.ndarray  #: (B,) ``integrators.STATUS_NAMES`` codes
    counts: np.ndarray  #: (B, 5) in the order of ``integrators.COUNTS``
    worst: np.ndarray  #: (B, 2) largest relative length error and spectral tail met
    samples: np.ndarray  #: (B, K, ny) states at the sample times (NaN: not reached)


def integrate_batch(method, constants, parameters, x0, t_end, options, cost=None, lanes=None,
                    t0=0.0, sample_times=None):
    """Integrate B cases of one model and truncation in parallel.

    ``method``: an ``integrators.METHODS`` value; ``constants``: what all cases
    share (``models.<model>.constants(problem)``; for the loop, its operators);
    ``parameters`` (B, P): each case's model parameters (``models.for_case``;
    for the loop, g0 and w); x0 (B, ny)
    the initial states at times t0; t0 and t_end scalars or length-B arrays;
    ``options`` the driver options (``integrators.step_options``).

    Returns a :class:`BatchRun` (y_final, t_final, status, counts, worst, samples): counts
    (B, 5) in the order of ``integrators.COUNTS``; worst (B, 2) the largest relative length
    error and spectral tail met along each trajectory (``integrators.integrate``); samples
    (B, K, ny) the states at ``sample_times`` (B, K), sorted per case within [t0, t_end]
    (the driver's dense output: sampling leaves the steps unchanged; NaN rows where a run
    stopped first; K = 0 without ``sample_times``).  ``cost``: an estimate of each case's
    cost (any monotone proxy; default: all equal) used to deal cases onto ``lanes``
    (default: the Numba thread count).
    """
    cases = x0.shape[0]
    y_final = np.full_like(x0, np.nan)
    t_final = np.zeros(cases)
    status = np.zeros(cases, dtype=np.int64)
    counts = np.zeros((cases, len(COUNTS)), dtype=np.int64)
    worst = np.zeros((cases, 2))
    t_samples = np.ascontiguousarray(np.zeros((cases, 0)) if sample_times is None else
                                     np.asarray(sample_times, float).reshape(cases, -1))
    samples = np.full((cases, t_samples.shape[1], x0.shape[1]), np.nan)
    as_array = lambda v: np.ascontiguousarray(np.broadcast_to(np.asarray(v, float), (cases,)))
    order = np.arange(cases) if cost is None else np.argsort(-np.asarray(cost, float), kind="stable")
    lanes = numba.get_num_threads() if lanes is None else int(lanes)
    parameters = np.ascontiguousarray(np.asarray(parameters, dtype=float).reshape(cases, -1))
    x0, t0, t_end = np.ascontiguousarray(x0), as_array(t0), as_array(t_end)
    outputs = (y_final, t_final, status, counts, worst, samples)
    if lanes == 1:  # serial, case by case: Python threads may each run one (the sweep's
        # work queue; integrate releases the GIL), while a parallel kernel is not to be
        # launched from several threads at once
        for b in order:
            status[b], t_final[b], y_final[b], counts[b], case_worst = integrate(
                method, case_problem(constants, parameters[b]), x0[b], t0[b], t_end[b],
                t_samples[b], options, samples[b])
            worst[b] = case_worst[:2]
    else:
        parallel_cases(method, constants, parameters, x0, t0, t_end, t_samples, options, order,
                       lanes, *outputs)
    return BatchRun(*outputs)


def __getattr__(name):
    """``integrate_cases``, this function's name until it met ``refinement.integrate_cases``:
    deprecated, kept for one release."""
    if name == "integrate_cases":
        from ._moved import warn_moved

        warn_moved("loopsim.batch.integrate_cases", "loopsim.batch.integrate_batch")
        return integrate_batch
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
