"""Dask against the local backend: the same sweep on this machine's threads and on a LocalCluster.

Usage: python benchmarks/bench_dask.py [--t-end 3] [--chunk-size 8] [--workers 2]

1. The 64-case grid of benchmarks/bench_ensemble.py (g0 = 10..350 x theta0 = 6..90 deg,
   n = 6), once on the local backend (2 threads: a prange kernel when the README's
   table was measured, a work queue since), once on a LocalCluster of 2 worker
   processes x 1 Numba thread, with each worker writing its chunks (write="worker") and
   with the chunks sent back to this process, which writes them (write="client").
   Every run is checked to give the same rows as the local run.
2. Per-task overhead: 64 tiny cases (t_end = 1e-6, one case per chunk = one task each)
   on the cluster, against the same 64 pieces run one by one here.
Cluster start-up and the workers' first kernel load (from the on-disk cache) are timed
apart and not counted in the sweeps.
"""
import argparse
import tempfile
import time

import pandas as pd

from loopsim import storage, sweeps

DETERMINISTIC = [c for c in storage.RESULT_SCHEMA.names if c != "wall_s"]


def timed(config, **options):
    with tempfile.TemporaryDirectory() as out:
        start = time.perf_counter()
        frame = sweeps.run_sweep(config, out, quiet=True, **options)
        return time.perf_counter() - start, frame


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=3.0)
    parser.add_argument("--chunk-size", type=int, default=8)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    from dask.distributed import Client, LocalCluster

    cases = sweeps.grid_cases(sweeps.parse_values("10:350:8", "--g0"),
                              sweeps.parse_values("6:90:8", "--theta0"), [6], 1)
    config = sweeps.SweepConfig(cases=cases, t_end=args.t_end, chunk_size=args.chunk_size)
    tiny = sweeps.SweepConfig(cases=cases, t_end=1e-6, chunk_size=1)
    timed(sweeps.SweepConfig(cases=cases[:2], t_end=0.01), threads=2)  # compile here

    local, reference = timed(config, threads=2)
    print(f"# {len(cases)} cases, n = 6, t_end = {args.t_end}, chunk size {args.chunk_size} "
          f"({config.n_chunks} tasks)")
    print(f"local backend, 2 threads:                {local:7.2f} s")

    start = time.perf_counter()
    cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                           dashboard_address=None)  # each task sets 1 Numba thread
    client = Client(cluster)
    started = time.perf_counter() - start
    address = cluster.scheduler_address
    warm, _ = timed(sweeps.SweepConfig(cases=cases[:args.workers * 2], t_end=0.01,
                                       chunk_size=1), scheduler=address, threads=1)
    print(f"LocalCluster start ({args.workers} workers):           {started:7.2f} s")
    print(f"workers' first kernel load (cache):      {warm:7.2f} s")
    for write in ("worker", "client"):
        wall, frame = timed(config, scheduler=address, threads=1, write=write)
        pd.testing.assert_frame_equal(frame[DETERMINISTIC], reference[DETERMINISTIC],
                                      check_exact=True)
        print(f"dask {args.workers} x 1 thread, {write} writes:      {wall:7.2f} s  "
              f"(overhead {100 * (wall / local - 1):+.0f}% against the local backend; rows identical)")

    dask_tiny, _ = timed(tiny, scheduler=address, threads=1)
    here_tiny, _ = timed(tiny, threads=1)
    per_task = dask_tiny * args.workers / tiny.n_chunks
    per_piece = here_tiny / tiny.n_chunks
    print(f"# per-task cost, {tiny.n_chunks} tiny tasks (t_end = 1e-6, 1 case each)")
    print(f"dask: {dask_tiny:.2f} s wall on {args.workers} workers = {1000 * per_task:.0f} ms "
          f"worker-time per task; here, one by one: {1000 * per_piece:.0f} ms per piece; "
          f"overhead {1000 * (per_task - per_piece):.0f} ms per task")
    client.close()
    cluster.close()


if __name__ == "__main__":
    main()
