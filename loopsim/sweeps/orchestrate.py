"""The top level of a sweep: :func:`run_sweep` (check, prepare the directory, plan the
pieces, hand them to a backend, read the table back) and its Python form :func:`sweep`."""
import dataclasses
import os

import numpy as np

from .. import io, seeding, validation
from ..config import (
    DEFAULT_AUTO_CHUNK_SIZE, DEFAULT_CHUNK_SIZE, DEFAULT_N, DEFAULT_PERTURBATION, SEED_TARGETS,
)
from .cases import SweepConfig, grid_cases, validate
from .chunks import canonical_chunks, covered_ids, pending_pieces
from .dask_backend import close_cluster, dask_client, run_dask
from .directory import prepare_directory
from .local import run_local
from .progress import Progress, case_weight
from .seeds_auto import run_seeds_auto
from .stopping import SweepInterrupted, stop_event, stop_on_signals


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
    try:
        fingerprint = prepare_directory(out, config, command_line or [])
        covered = io.chunk_files(out)
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
    return io.read_results(out)


def sweep(g0, theta0_deg, out, *, n=6, seeds=1, method=None, quiet=True, threads=None,
          scheduler=None, local_cluster=False, workers=None, **options):
    """The Python form of ``loopsim sweep``: every (g0, θ0, seed) of the grid into the
    sweep directory ``out`` (made, or resumed), returned as the results DataFrame
    (:func:`io.read_results`).

    ``g0`` and ``theta0_deg``: values (numbers or sequences); ``n``: an order, a
    sequence of orders, or "auto"; ``seeds``: seeds 0..seeds-1 per point, or "auto":
    seeds added per cell until its answer is sharp (``--seeds auto``: rounds of sweeps,
    ``sweeps.seeds_auto``; its targets ``p_halfwidth``, ``tilt_halfwidth`` (deg),
    ``min_seeds``, ``max_seeds`` as keywords, defaults of ``seeding.SeedTargets``; the
    rows get a ``round`` column; the stop table: ``io.read_stop_table(out)``);
    ``method``: as in ``simulate`` (default rkf45 at a fixed n, auto with ``n="auto"``).
    Every other keyword is a :class:`SweepConfig` field under its own name (``t_end``,
    ``rtol``, ``atol``, ``w``, ``early_stop``, ``twin``, ``n_max``, ``tail_tol``,
    ``chunk_size``, ...) or ``perturbation``.  Backends as :func:`run_sweep`.  The
    directory is the one the command line writes: either may resume the other.
    """
    auto = isinstance(n, str)
    if auto and n != "auto":
        raise ValueError(f"n must be an order, a sequence of orders or 'auto', got {n!r}")
    seeds_auto = isinstance(seeds, str)
    if seeds_auto and seeds != "auto":
        raise ValueError(f"seeds must be a count or 'auto', got {seeds!r}")
    targets = {SEED_TARGETS[k][0]: options.pop(k) for k in list(options) if k in SEED_TARGETS}
    if targets and not seeds_auto:
        raise ValueError(f"{sorted(targets)} apply only with seeds='auto'")
    perturbation = options.pop("perturbation", DEFAULT_PERTURBATION)
    unknown = set(options) - {f.name for f in dataclasses.fields(SweepConfig)} - {"cases"}
    if unknown or "cases" in options:
        raise ValueError(f"unknown sweep option(s) {sorted(unknown or {'cases'})}")
    axes = [np.atleast_1d(np.asarray(v, dtype=float)).tolist() for v in (g0, theta0_deg)]
    orders = [DEFAULT_N] if auto else [int(v) for v in np.atleast_1d(n)]
    seeds = 1 if seeds_auto else validation.check_integer("seeds", seeds, 1)
    cases = grid_cases(axes[0], axes[1], orders, seeds, perturbation)
    options.setdefault("chunk_size", DEFAULT_AUTO_CHUNK_SIZE if auto else DEFAULT_CHUNK_SIZE)
    config = SweepConfig(cases=cases, method=method or ("auto" if auto else "rkf45"),
                         n_auto=auto, **options)
    backend = dict(threads=threads, quiet=quiet, command_line=["loopsim.sweep(...)"],
                   scheduler=scheduler, local_cluster=local_cluster, workers=workers)
    if seeds_auto:
        rows, _ = run_seeds_auto(
            config, os.fspath(out), seeding.SeedTargets(**targets),
            run_round=lambda round_config, directory, weights: run_sweep(
                round_config, directory, weights=weights, **backend),
            command_line=backend["command_line"])
        return rows
    return run_sweep(config, os.fspath(out), **backend)
