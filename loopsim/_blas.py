"""One BLAS thread per loopsim worker.

loopsim runs cases in parallel itself (a work queue of threads, ``prange`` over
cases, Dask workers), and each case's kernels call BLAS through ``np.dot`` on
small matrices (scipy's OpenBLAS; M × M with M = 4n + 1).  OpenBLAS splits large
enough products over its own thread pool, one per core, so a sweep on all cores
runs threads² threads: a 4-case n = 24 sweep on 2 threads took 80.6 s against
17.2 s with one BLAS thread (docs/studies/performance.md, "BLAS threads").  Every integration
therefore runs under threadpoolctl's limit of one BLAS thread.

The limit is process-wide, and threadpoolctl lets one Python thread at a time
control OpenBLAS, so the first holder owns it: its entry sets the limit and its exit
restores the caller's setting; entries from other threads while it is held (a
sweep's worker threads, inside the sweep's own limit) change nothing.  A worker
abandoned by an interrupted sweep may therefore finish its case with BLAS threads
again; the caller's setting is never left changed.
"""
import contextlib
import threading

from threadpoolctl import threadpool_limits

_lock = threading.Lock()
_owner = None


@contextlib.contextmanager
def one_blas_thread():
    """Context manager: BLAS libraries limited to one thread inside, as before outside
    (nested and concurrent entries: the first holder's limit)."""
    global _owner
    with _lock:
        first = _owner is None
        if first:
            _owner = threading.current_thread()
    if not first:
        yield
        return
    try:
        with threadpool_limits(limits=1, user_api="blas"):
            yield
    finally:
        with _lock:
            _owner = None
