"""The top level of a sweep: :func:`run_sweep` (check, prepare the directory, plan the
pieces, hand them to a backend, read the table back) and its Python form :func:`sweep`."""
import json
import os

import numpy as np

from .. import seeds_auto_rule, storage, validation
from ..defaults import (
    DEFAULT_ATOL, DEFAULT_AUTO_CHUNK_SIZE, DEFAULT_CHUNK_SIZE, DEFAULT_LENGTH_TOL,
    DEFAULT_MAX_STEPS, DEFAULT_N, DEFAULT_N_MAX, DEFAULT_PERTURBATION, DEFAULT_RTOL,
    DEFAULT_STEADY_INTERVAL, DEFAULT_STEADY_TOL, DEFAULT_T_END, DEFAULT_TAIL_TOL, DEFAULT_W,
    SEED_TARGETS,
)
from ..outcomes import Thresholds
from .cases import SweepConfig, grid_cases, validate
from .chunks import canonical_chunks, covered_ids, pending_pieces
from .dask_backend import close_cluster, dask_client, run_dask
from . import lock
from .directory import prepare_directory
from .local import run_local
from .progress import Progress, case_weight
from .seeds_auto import run_seeds_auto
from .signals import SweepInterrupted, stop_event, stop_on_signals


def run_sweep(config, out, threads=None, quiet=False, command_line=None, *, scheduler=None,
              local_cluster=False, workers=None, shard=None, unit=None, write="client",
              progress_interval=30.0, stream=None, weights=None):
    """Run (or resume) a sweep into directory ``out``; returns the results DataFrame.

    Backends: this machine's cores (default; ``threads`` worker threads, default all
    cores, serving a work queue of cases: :func:`run_local`), a
    Dask cluster at ``scheduler`` or, with ``local_cluster``, a new Dask LocalCluster
    of ``workers`` processes (``threads`` Numba threads each, default 1).  ``shard``
    (i, n): only the chunks k with k % n == i (job arrays).  ``unit``: positions per
    task of the local work queue (default 1: a signal loses at most the cases in
    flight).
    The directory is held (``lock``) before any case runs: a second command into it is
    refused while this one runs, unless it is another shard of the same sweep.
    SIGINT/SIGTERM: finished cases are written, then :class:`SweepInterrupted` is
    raised (the running tasks' cases are lost; called from Python, their worker threads
    run on until their kernel returns, then stop).
    ``write`` (Dask): "client" (default: pieces come back and this process writes them;
    no shared filesystem needed) or "worker" (each worker writes its pieces into ``out``,
    which it must see at the same path); measured equal (docs/sweeps.md, "Dask and job arrays").
    ``weights``: {case id: expected cost} (``--seeds auto`` passes its cells' measured
    costs; default :func:`progress.case_weight`'s estimate): the local backend starts the
    costliest pieces first, so that a heavy case does not run alone at the end, and the
    ETA is weighted by them.
    """
    import numba

    validate(config)
    if shard is not None and not (0 <= shard[0] < shard[1]):
        raise ValueError(f"shard must be I/N with 0 <= I < N, got {shard[0]}/{shard[1]}")
    distributed = scheduler is not None or local_cluster
    if write not in ("worker", "client"):
        raise ValueError(f"write must be 'worker' or 'client', got {write!r}")
    for name, value in (("threads", threads), ("unit", unit)):
        if value is not None:
            validation.check_integer(name, value, 1)
    if workers is not None:
        validation.check_count("workers", workers, 1, validation.MAX_WORKERS,
                               "this machine's cores: each worker is a process that compiles "
                               "its own kernels, and more than the cores only compete")
    client = cluster = None
    stop = stop_event()
    if distributed:  # connected first: a scheduler refused leaves no directory behind
        workers = workers or max(1, numba.config.NUMBA_NUM_THREADS // (threads or 1))
        client, cluster = dask_client(scheduler, workers)
    held = None
    try:
        held = _hold(out, config, shard, command_line)
        fingerprint = prepare_directory(out, config, command_line or [])
        covered = storage.chunk_files(out)
        pieces = pending_pieces(config, covered, shard)
        mine = covered_ids(config, [(c.start, c.stop)
                                     for k, c in enumerate(canonical_chunks(config))
                                     if shard is None or k % shard[1] == shard[0]])
        done = set(covered_ids(config, covered)) & set(mine)
        if weights is None:
            weights = {i: case_weight(case, config.n_auto) for i, case in enumerate(config.cases)}
        progress = Progress({i: weights[i] for i in mine}, done, quiet, stream,
                            progress_interval)
        with stop_on_signals(stop):
            if distributed and pieces:
                run_dask(config, out, fingerprint, pieces, threads or (1 if cluster else None),
                          progress, stop, client, write)
            elif pieces:
                threads = threads or numba.config.NUMBA_NUM_THREADS
                run_local(config, out, fingerprint, pieces, threads, unit or 1, progress,
                          stop, weights)
    finally:
        if held is not None:
            held.release()
        if client is not None:
            grace = 1 if stop.is_set() else None  # on a signal: no waiting for tasks
            if grace is not None:  # connections cut short are expected now, not errors
                import logging

                logging.getLogger("distributed").setLevel(logging.CRITICAL)
            client.close(**({} if grace is None else dict(timeout=grace)))
            if cluster is not None:
                close_cluster(cluster, grace)
    progress.close()
    if stop.is_set():
        raise SweepInterrupted(stop.signum, out, progress.done, progress.total)
    return storage.read_results(out)


def warn_mixed_columns(frame, out):
    """A ``LoopsimWarning`` (one line) where the rows of the sweep in ``out`` mix rows with
    and without a column (a resume across releases: ``storage.mixed_columns_text``)."""
    import warnings

    from ..result import LoopsimWarning

    text = storage.mixed_columns_text(frame)
    if text is not None:
        warnings.warn(f"{out}: {text}", LoopsimWarning, stacklevel=3)
    return frame


def _hold(out, config, shard, command_line):
    """Hold ``out`` for this sweep (``lock.hold``) once the checks that need no directory
    have passed (a layout-1 directory, a round of a ``--seeds auto`` sweep planned
    otherwise): a refused command makes no directory."""
    fingerprint = storage.config_fingerprint(json.loads(json.dumps(config.as_dict())))
    storage.check_layout(out)
    storage.check_round_directory(out, fingerprint)
    return lock.hold(out, lock.holder(fingerprint, shard), command_line)


def sweep(g0, theta0_deg, out, *, n="auto", seeds=1, method=None, t_end=DEFAULT_T_END,
          rtol=DEFAULT_RTOL, atol=DEFAULT_ATOL, w=DEFAULT_W, perturbation=DEFAULT_PERTURBATION,
          twin=True, early_stop=True, n_max=DEFAULT_N_MAX, tail_tol=DEFAULT_TAIL_TOL,
          model="local", slenderness=None, max_steps=DEFAULT_MAX_STEPS,
          length_tol=DEFAULT_LENGTH_TOL, steady_interval=DEFAULT_STEADY_INTERVAL,
          steady_tol=DEFAULT_STEADY_TOL, thresholds=Thresholds(), snapshots_for=(),
          snapshot_count=101, chunk_size=None, p_halfwidth=None, tilt_halfwidth=None,
          min_seeds=None, max_seeds=None, check_seeds=None, quiet=True, threads=None,
          scheduler=None, local_cluster=False, workers=None):
    """Run (or resume) a sweep over a grid of (g0, θ0, n, seed): the Python form of
    ``loopsim sweep``.

    Every case of the grid is integrated into the sweep directory ``out`` (made, or
    resumed: the directory is the one the command line writes, and either may resume the
    other), and the rows are read back (``loopsim.read_results``).

    Parameters
    ----------
    g0 : float or sequence of float
        Gravity over bending stiffness, L³ g ρ_L / (8π³ EI) (dimensionless, >= 0).
    theta0_deg : float or sequence of float
        Initial tilts of the loop's plane to the horizontal, in degrees, in [0, 90].
    out : str or os.PathLike
        The sweep directory.
    n : int, sequence of int or "auto", default "auto"
        Truncation orders (1..128), or "auto": every case starts at n = 6 and is
        restarted from t = 0 at the next order of ``defaults.AUTO_ORDERS`` (up to ``n_max``)
        whenever its spectral tail passes ``tail_tol``.  The paper's scheme is
        ``n=6, method="rkf45"``.
    seeds : int or "auto", default 1
        Seeds 0..seeds-1 per grid point, or "auto": rounds of seeds per cell until its
        answer is sharp (``p_halfwidth``, ``tilt_halfwidth``), deterministic, or at
        ``max_seeds`` (docs/distributions.md); the rows then get a ``round`` column and
        the stop table is ``loopsim.storage.read_stop_table(out)``.
    method : {"rkf45", "radau5", "auto"} or None, default None
        The integrator; None: "auto" (chosen per case, ``refinement.auto_method``) with
        ``n="auto"`` and "rkf45" (the paper's) at a fixed n.
    t_end : float, default 10.0
        Final time, in t_u (docs/model.md, "Units").
    rtol : float, default 1e-6
        Relative tolerance of the time integration (dimensionless).
    atol : float, default 1e-9
        Absolute tolerance on the shape coefficients, in L/2π.
    w : float, default 10.0
        Length-penalty rate of the inextensibility constraint, in 1/t_u.
    perturbation : float, default 1e-3
        RMS size of the seeded initial perturbation, in L/2π (0: the exact circle).
    twin : bool, default True
        Also run the twin at 10x stricter tolerances that says whether the outcome is
        ``determined`` (``loopsim.outcomes``); run and twin together cost about 2.7 times the
        run alone (docs/auto-and-determinacy.md).
    early_stop : bool, default True
        Stop a case once its shape and tilt are steady (``steady_tol`` per
        ``steady_interval``; docs/sweeps.md): a sweep wants each case's terminal state,
        not its states at later times.  ``loopsim.simulate`` integrates to the end by
        default instead (its ``steady_tol=None``): a single run returns its states at the
        requested times.
    n_max : int, default 32
        With ``n="auto"``: the highest order a run may reach (also capped by the model's,
        for nonlocal).
    tail_tol : float, default 1e-5
        With ``n="auto"``: the spectral-tail tolerance (dimensionless) that restarts a run
        at the next order.
    model : {"local", "nonlocal"}, default "local"
        The hydrodynamics: the paper's local slender-body theory, or full slender-body
        theory (needs ``slenderness``; docs/nonlocal.md), whose n must stay below its
        highest order (``models.highest_order``).
    slenderness : float or None, default None
        With ``model="nonlocal"``: ε = a/L, filament radius over loop length
        (dimensionless, in (0, 0.05]).
    max_steps : int, default 2000000
        Most time steps of a run.
    length_tol : float, default 0.25
        Relative length error (dimensionless) at which a run stops as failed.
    steady_interval : float, default 0.5
        Interval of the steady-state test (``steady_tol``), in t_u.
    steady_tol : float, default 1e-6
        Change per interval (dimensionless) below which the state is steady.
    thresholds : loopsim.outcomes.Thresholds, default Thresholds()
        The regime, resolution and determinacy thresholds.
    snapshots_for : sequence of int, default ()
        Case ids whose trajectories are stored as snapshots.
    snapshot_count : int, default 101
        Snapshots per stored trajectory (equally spaced times, both ends included).
    chunk_size : int or None, default None
        Cases per result file; None: 32, or 4 with ``n="auto"``.
    p_halfwidth, tilt_halfwidth, min_seeds, max_seeds, check_seeds : float, int or None, default None
        With ``seeds="auto"`` only: its targets (a probability; degrees; counts); None:
        the values of ``loopsim.defaults.SEED_TARGETS`` (0.15, 2.5, 4, 64, 8).
    quiet : bool, default True
        No progress line.
    threads : int or None, default None
        Worker threads (None: all cores).
    scheduler : str or None, default None
        Address of a Dask scheduler to send the chunks to.
    local_cluster : bool, default False
        Start a Dask LocalCluster of ``workers`` processes.
    workers : int or None, default None
        Worker processes of the LocalCluster.

    Returns
    -------
    pandas.DataFrame
        One row per case, sorted by ``case_id``: the columns of
        ``loopsim.columns.RESULT_COLUMNS`` (each with its unit in
        ``frame.attrs["loopsim"]["columns"]``).

    Raises
    ------
    TypeError
        An unknown keyword argument.
    ValueError
        A bad value (named in the message), a seed target without ``seeds="auto"``, or
        ``out`` holding another sweep.
    OSError
        The directory cannot be written.
    loopsim.sweeps.SweepInterrupted
        SIGINT or SIGTERM during the sweep (finished cases are kept).

    Examples
    --------
    >>> import loopsim
    >>> rows = loopsim.sweep([10.0, 40.0], 30.0, "runs/two", n=6, t_end=0.5, twin=False)
    >>> rows[["g0", "regime", "theta_final_deg"]].round(3)
         g0  regime  theta_final_deg
    0  10.0  stable           29.998
    1  40.0  stable           29.984
    """
    auto = isinstance(n, str)
    if auto and n != "auto":
        raise ValueError(f"n must be an order, a sequence of orders or 'auto', got {n!r}")
    seeds_auto = isinstance(seeds, str)
    if seeds_auto and seeds != "auto":
        raise ValueError(f"seeds must be a count or 'auto', got {seeds!r}")
    given = dict(p_halfwidth=p_halfwidth, tilt_halfwidth=tilt_halfwidth, min_seeds=min_seeds,
                 max_seeds=max_seeds, check_seeds=check_seeds)
    targets = {SEED_TARGETS[k][0]: v for k, v in given.items() if v is not None}
    if targets and not seeds_auto:
        raise ValueError(f"{sorted(targets)} apply only with seeds='auto'")
    axes = [np.atleast_1d(np.asarray(v, dtype=float)).tolist() for v in (g0, theta0_deg)]
    orders = [DEFAULT_N] if auto else [int(v) for v in np.atleast_1d(n)]
    seeds = 1 if seeds_auto else validation.check_integer("seeds", seeds, 1)
    cases = grid_cases(axes[0], axes[1], orders, seeds, perturbation)
    if chunk_size is None:
        chunk_size = DEFAULT_AUTO_CHUNK_SIZE if auto else DEFAULT_CHUNK_SIZE
    config = SweepConfig(
        cases=cases, method=method or ("auto" if auto else "rkf45"), n_auto=auto,
        t_end=t_end, rtol=rtol, atol=atol, w=w, twin=twin, early_stop=early_stop,
        n_max=n_max, tail_tol=tail_tol, model=model, slenderness=slenderness,
        max_steps=max_steps, length_tol=length_tol, steady_interval=steady_interval,
        steady_tol=steady_tol, thresholds=thresholds, snapshots_for=list(snapshots_for),
        snapshot_count=snapshot_count, chunk_size=chunk_size)
    backend = dict(threads=threads, quiet=quiet, command_line=["loopsim.sweep(...)"],
                   scheduler=scheduler, local_cluster=local_cluster, workers=workers)
    if seeds_auto:
        rows, _ = run_seeds_auto(
            config, os.fspath(out), seeds_auto_rule.SeedTargets(**targets),
            run_round=lambda round_config, directory, weights: run_sweep(
                round_config, directory, weights=weights, **backend),
            command_line=backend["command_line"])
        return warn_mixed_columns(rows, out)
    return warn_mixed_columns(run_sweep(config, os.fspath(out), **backend), out)
