"""The Dask backend: a sweep's pieces as tasks of a Dask cluster (a scheduler's, or a
LocalCluster started here)."""
import re

from .directory import write_piece
from .progress import case_seconds, failures
from .runner import run_piece


def dask_client(scheduler, workers):
    """(client, cluster or None): connected to ``scheduler``, or to a new LocalCluster of
    ``workers`` processes, one task at a time each."""
    import logging

    from dask.distributed import Client, LocalCluster

    if scheduler is not None:
        if not re.fullmatch(r"(\w+://)?[^\s:/]+:\d+", str(scheduler)):
            raise ValueError(f"--scheduler must be an address like tcp://host:8786, got "
                             f"{scheduler!r}")
        try:
            return Client(scheduler, timeout="30s"), None
        except (OSError, ValueError, TypeError) as exc:
            raise ValueError(f"cannot connect to the Dask scheduler {scheduler!r}: "
                             f"{str(exc).splitlines()[0] if str(exc) else type(exc).__name__}"
                             ) from None
    # NUMBA_NUM_THREADS is left alone: a worker process that compiles re-reads it and
    # refuses a value other than the one its thread pool started with (seen with env=
    # here); each task sets its own thread count instead (run_piece)
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                           dashboard_address=None, silence_logs=logging.ERROR)
    return Client(cluster), cluster


def close_cluster(cluster, grace):
    """Close a LocalCluster; with ``grace`` (seconds, after a signal) its worker processes,
    busy in a kernel that cannot be cut short, are killed rather than waited for."""
    if grace is None:
        cluster.close()
        return
    for nanny in cluster.workers.values():
        try:
            nanny.process.process.kill()
        except Exception:  # noqa: BLE001 - gone already, or another distributed layout
            pass
    cluster.close(timeout=grace)


def run_dask(config, out, fingerprint, pieces, threads, progress, stop, client, write):
    """The pieces as Dask tasks (one per piece); the configuration is sent once to every
    worker.  ``write``: "worker" (each worker writes its piece into ``out``, a shared
    directory) or "client" (results come back and this process writes them)."""
    shared = client.scatter(config, broadcast=True)
    futures = [client.submit(run_piece, shared, piece, threads,
                             out if write == "worker" else None, fingerprint, pure=False)
               for piece in pieces]
    pending = set(futures)
    try:
        while pending and not stop.is_set():
            finished = [f for f in pending if f.done()]
            if not finished:
                stop.wait(0.05)
                continue
            for future in finished:
                pending.discard(future)
                piece, table, snapshots = future.result()
                if write == "client":
                    write_piece(out, fingerprint, piece, table, snapshots)
                progress.update(table.column("case_id").to_pylist(), failures(table),
                                case_seconds(table))
    finally:
        if pending:
            client.cancel(list(pending))
