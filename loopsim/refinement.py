"""Automatic truncation (``n="auto"``): each case runs at the smallest order of its
ladder that keeps it resolved *from its start*.

A case starts at the lowest order of its ladder (``orders``).  After every
accepted step the driver measures the spectral tail, the share of the loop's
deformation carried by its top two Fourier modes (``models.local_sbt.spectral_tail``);
once it passes ``tail_tol`` the driver stops with status REFINE and the case is
restarted **from its start at t0** at the next order of the ladder (the start
zero-padded: exact, ``spectral.resize``).  At the top order the tail is only
recorded.  So an ``n="auto"`` result is the fixed-order run at ``n_used`` from the
same start, bit for bit: nothing of a lower order's dynamics is carried into it.

Why restart rather than go on from the refinement time (which an earlier version
did): a 3D transient amplifies what a lower order got wrong before its tail passed
the tolerance.  Going on gave terminal tilts up to 18 degrees off same-start fixed
runs on hard 3D cases (g0 = 150); a restart carries nothing over.  The cost is the lower orders'
partial runs, which end where their tail passes ``tail_tol``, early in a 3D
transient (counted in the case's ``nfev`` and ``wall_s``; docs/auto-and-determinacy.md).

Everything here is orchestration of the compiled driver, level by level: a level
is one call of ``integrators.integrate`` (one case) or ``batch.integrate_batch``
(many cases in parallel).
"""
import typing

import numpy as np

from . import batch, integrators, models, spectral, validation
from ._blas import one_blas_thread
from .defaults import AUTO_ORDERS, DEFAULT_N
from .integrators.control import REFINE

#: Where ``n="auto"`` starts for the tilted circle (the paper's resolution).
AUTO_START = DEFAULT_N
#: The ``method`` values a user may give: the integrators, or "auto" (``auto_method``).
METHOD_CHOICES = tuple(integrators.METHODS) + ("auto",)
#: Above this q0 the circle is linearly unstable out of its plane (full linearisation,
#: docs/stability.md): the case is expected to turn 3D.
Q_OUT_OF_PLANE = 10.6493


def auto_method(q0, n, refine):
    """The integrator for a case: RKF45 for a fixed n ≤ 6 run expected to turn 3D (q0
    above the out-of-plane threshold: short explicit steps are cheapest while the
    shape changes fast), Radau IIA otherwise (stiffness grows like n⁴; stable and
    in-plane loops settle and long implicit steps win).  Evidence: docs/choosing-n-method-rtol.md, "Which
    integrator"."""
    return "rkf45" if (not refine and n <= 6 and q0 > Q_OUT_OF_PLANE) else "radau5"


def orders(n_start, n_max):
    """The ladder: ``defaults.AUTO_ORDERS`` strictly between n_start and n_max, with both
    ends included (n_start ≤ n_max)."""
    n_start = validation.check_integer("n", n_start, 1)
    n_max = validation.check_integer("n_max", n_max, n_start)
    return (n_start,) + tuple(n for n in AUTO_ORDERS if n_start < n < n_max) + (
        (n_max,) if n_max > n_start else ())


def level_options(options, tail_tol, top):
    """Driver options of one level: refine past ``tail_tol``, except at the top order."""
    return options._replace(resolution_tol=np.inf if top else float(tail_tol))


class CaseRun(typing.NamedTuple):
    """What ``integrate_case`` returns (a tuple: it unpacks in this order)."""

    status: int  #: ``integrators.STATUS_NAMES`` code of the last level
    t_final: float  #: time reached, in t_u
    x_final: np.ndarray  #: (3, 2 n_used + 1) terminal coefficients, in L/2π
    n_used: int  #: the last order reached
    counts: np.ndarray  #: ``integrators.COUNTS``, summed over the levels
    worst: np.ndarray  #: [largest length error, largest spectral tail] of the last level
    x_out: np.ndarray  #: (len(t_eval), 3, 2 n_used + 1) states at t_eval (NaN: not reached)


class CasesRun(typing.NamedTuple):
    """What ``integrate_cases`` returns, per case b (a tuple: it unpacks in this order)."""

    x_final: list  #: B arrays (3, 2 n_used[b] + 1), in L/2π
    n_used: np.ndarray  #: (B,) the last order each case reached
    t_final: np.ndarray  #: (B,) time reached, in t_u
    status: np.ndarray  #: (B,) ``integrators.STATUS_NAMES`` codes
    counts: np.ndarray  #: (B, len(integrators.COUNTS)), summed over the levels
    worst: np.ndarray  #: (B, 2) largest length error and spectral tail of the last level
    samples: list  #: B arrays (K, 3, 2 n_used + 1): the states at the sample times


def integrate_case(method, g0, w, x0, t0, t_end, t_eval, options, ladder, tail_tol,
                   model=models.LOCAL):
    """One case of ``model`` (``models.Model``) up the ladder (from x0 (3, 2 ladder[0] + 1)
    at t0), each order from t0.

    Returns a ``CaseRun`` (status, t_final, x_final, n_used, counts, worst, x_out): counts as
    ``integrators.integrate``, summed over the levels (the work of every level);
    worst = [largest length error, largest spectral tail] of the last level's run;
    n_used the last order reached; x_out (len(t_eval), 3, 2 n_used + 1) the states at
    the requested times (NaN where not reached).
    """
    x0 = np.asarray(x0, dtype=float)
    t_eval = np.ascontiguousarray(t_eval, dtype=float)
    counts = np.zeros(len(integrators.COUNTS), dtype=np.int64)
    for level, n in enumerate(ladder):
        x_out = np.full((t_eval.size, 3, spectral.n_coeffs(n)), np.nan)
        rows = x_out.reshape(t_eval.size, 3 * spectral.n_coeffs(n))
        y0 = spectral.resize(x0, n).ravel()
        with one_blas_thread():  # always with output arrays (empty for a twin): the one
            # specialisation of the driver a run and its twin, and a sweep, compile
            status, t, y, level_counts, worst = integrators.integrate(
                method, models.make_problem(model, n, g0, w), y0, t0, t_end, t_eval,
                level_options(options, tail_tol, level == len(ladder) - 1), rows)
        counts += level_counts
        if status != REFINE:
            break
    return CaseRun(int(status), float(t), y.reshape(3, -1), n, counts, worst[:2].copy(), x_out)


def integrate_cases(method, parameters, x0, t_end, options, ladder, tail_tol, cost=None,
                    model=models.LOCAL, sample_times=None):
    """Many cases of ``model`` up the ladder, each level in the parallel batch kernel, each
    order from t0.

    x0 (B, 3, 2 ladder[0] + 1); parameters (B, P) each case's
    ``models.case_parameters``; sample_times (B, K) or None (K = 0), sorted times within
    [0, t_end] per case.  Returns a ``CasesRun`` (x_final, n_used, t_final, status,
    counts, worst, samples): x_final a list of B arrays (3, 2 n_used + 1); counts summed
    over the levels; the others those of each case's last level (samples: the states at
    the sample times, from the driver's dense output).
    """
    cases = len(x0)
    x0 = [np.asarray(xb, dtype=float) for xb in x0]
    x = list(x0)
    parameters = np.asarray(parameters, dtype=float).reshape(cases, -1)
    cost = np.ones(cases) if cost is None else np.asarray(cost, dtype=float)
    t_end = np.broadcast_to(np.asarray(t_end, dtype=float), (cases,))
    t = np.zeros(cases)
    status = np.full(cases, REFINE, dtype=np.int64)
    counts = np.zeros((cases, len(integrators.COUNTS)), dtype=np.int64)
    worst = np.zeros((cases, 2))
    n_used = np.full(cases, ladder[0], dtype=np.int64)
    sample_times = (np.zeros((cases, 0)) if sample_times is None else
                    np.asarray(sample_times, dtype=float).reshape(cases, -1))
    samples = [None] * cases
    for level, n in enumerate(ladder):
        active = np.flatnonzero(status == REFINE)
        if not active.size:
            break
        with one_blas_thread():  # the cases run in parallel already
            level_run = batch.integrate_batch(
                method, models.case_constants(model, n), parameters[active],
                np.array([spectral.resize(x0[b], n).ravel() for b in active]), t_end[active],
                level_options(options, tail_tol, level == len(ladder) - 1),
                cost=cost[active], sample_times=sample_times[active])
        for row, b in enumerate(active):
            x[b] = level_run.y_final[row].reshape(3, -1)
            t[b] = level_run.t_final[row]
            status[b] = level_run.status[row]
            counts[b] += level_run.counts[row]
            worst[b] = level_run.worst[row][:2]
            n_used[b] = n
            samples[b] = level_run.samples[row].reshape(sample_times.shape[1], 3,
                                                        spectral.n_coeffs(n))
    return CasesRun(x, n_used, t, status, counts, worst, samples)
