#!/bin/bash
# A loopsim sweep as a SLURM job array, no scheduler (not run in CI).
#   sbatch scripts/slurm_array.sh
# Each array task runs the same command with --shard I/N: it computes only the chunks
# k with k % N == I and writes them into the shared --out directory (atomic renames;
# the shards never write the same file). Re-submitting the array resumes: finished
# chunks are skipped. Check the whole sweep afterwards with
#   python -c "import loopsim; print(len(loopsim.read_results('/shared/runs/phase3d')))"
# Exit status per task: 0 every case ok, 1 some case failed (rows kept: rerun them
# with `loopsim sweep --rerun-failed DIR --method radau5`), 2 bad input, 130/143 signal.
# PBS: the same with #PBS -J 0-15 and $PBS_ARRAY_INDEX.
#SBATCH --job-name=loopsim-sweep
#SBATCH --array=0-15
#SBATCH --cpus-per-task=4
#SBATCH --time=12:00:00
#SBATCH --mem=8G
#SBATCH --signal=TERM@120
set -euo pipefail
N=${SLURM_ARRAY_TASK_COUNT:-16}
export NUMBA_NUM_THREADS=${SLURM_CPUS_PER_TASK:-4}
exec loopsim sweep --g0 10:350:60 --theta0 6:90:50 --n 16 --seeds 3 \
    --out /shared/runs/phase3d --threads "$NUMBA_NUM_THREADS" \
    --shard "${SLURM_ARRAY_TASK_ID}/${N}"
