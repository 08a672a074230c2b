"""A loopsim sweep on a SLURM cluster through dask-jobqueue (not run in CI; needs
``pip install dask-jobqueue`` and a SLURM site).

Usage (on the login node, inside the environment where loopsim is installed):

    python scripts/slurm_dask.py --jobs 25 --cores 4 -- \
        --g0 10:350:60 --theta0 6:90:50 --n 16 --seeds 3 --out /shared/runs/phase3d

Each SLURM job is one Dask worker process with ``--cores`` Numba threads (the prange
kernel inside each task) and one task at a time; chunks (``--chunk-size``, default 32
cases) are the tasks.  The finished chunks come back to this process, which writes
them into ``--out`` (so only this node needs the directory).  Ctrl-C or a lost login
session stops the sweep; the same command resumes it.  Account, partition, walltime and
memory are site settings: edit CLUSTER below.  With no scheduler at all, use a job array
instead: scripts/slurm_array.sh.
"""
import argparse
import sys

CLUSTER = dict(
    queue="compute",          # partition
    account=None,             # your allocation, if the site needs one
    walltime="12:00:00",
    memory="8GB",             # per job: n = 16 needs well under 1 GB per thread
    processes=1,              # one worker process per job
    job_extra_directives=[],  # e.g. ["--qos=normal"]
)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--jobs", type=int, default=10, help="SLURM jobs = Dask workers")
    parser.add_argument("--cores", type=int, default=4, help="cores per job = Numba threads")
    parser.add_argument("sweep", nargs=argparse.REMAINDER,
                        help="after --: the arguments of `loopsim sweep`")
    args = parser.parse_args()
    sweep = [a for a in args.sweep if a != "--"]

    from dask_jobqueue import SLURMCluster

    from loopsim.cli import main as loopsim

    # cores=1: one Dask thread per worker, so one task (chunk) at a time; job_cpu books the
    # job's cores for the task's Numba threads
    cluster = SLURMCluster(cores=1, job_cpu=args.cores,
                           job_script_prologue=[f"export NUMBA_NUM_THREADS={args.cores}"],
                           **{k: v for k, v in CLUSTER.items() if v is not None})
    cluster.scale(jobs=args.jobs)
    try:
        return loopsim(["sweep", *sweep, "--scheduler", cluster.scheduler_address,
                        "--threads", str(args.cores)])
    finally:
        cluster.close()


if __name__ == "__main__":
    sys.exit(main())
