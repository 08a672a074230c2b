"""One BLAS thread per loopsim worker.

loopsim runs cases in parallel itself (``prange`` over cases, Dask workers), and
each case's kernels call BLAS through ``np.dot`` on small matrices (scipy's
OpenBLAS; M × M with M = 4n + 1).  OpenBLAS splits large enough products
over its own thread pool, one per core, so a sweep on all cores runs threads²
threads: a 4-case n = 24 sweep on 2 threads took 80.6 s against 17.2 s with one
BLAS thread (README, "BLAS threads").  Every integration therefore runs under
threadpoolctl's limit of one BLAS thread, restored on exit.
"""
from threadpoolctl import threadpool_limits


def one_blas_thread():
    """Context manager: BLAS libraries limited to one thread inside, as before outside."""
    return threadpool_limits(limits=1, user_api="blas")
