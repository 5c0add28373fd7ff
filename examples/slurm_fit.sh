#!/bin/bash
# A data-parallel fit of a collection on a Slurm cluster (docs/mpi.md).
# Submit from a directory on a file system every node sees:
#   sbatch examples/slurm_fit.sh shapes.txt runs/family
# Each rank trains a contiguous block of the shapes (at most one rank per shape);
# rank 0 writes DIR. At the time limit Slurm sends SIGTERM to every rank
# (--signal below: 5 minutes early); the ranks agree on it at the next step and
# rank 0 writes a checkpoint, atomically, so a kill before it ends leaves the
# previous one intact. sbatch again with the same DIR resumes the run.
#SBATCH --job-name=jsatlas-fit
#SBATCH --nodes=4
#SBATCH --ntasks-per-node=8
#SBATCH --cpus-per-task=4
#SBATCH --time=04:00:00
#SBATCH --output=%x-%j.out
#SBATCH --signal=TERM@300
set -euo pipefail
list=${1:?usage: sbatch slurm_fit.sh SHAPES.txt DIR}
dir=${2:?usage: sbatch slurm_fit.sh SHAPES.txt DIR}
# Threads per rank: the cores Slurm gave the task. Results depend on the seed and
# the thread count, and (to float rounding) on the number of ranks.
threads=${SLURM_CPUS_PER_TASK:-1}
export OMP_PROC_BIND=close OMP_PLACES=cores
if [ -f "$dir/model.ckpt" ]; then
  # A run stopped by an earlier job (its settings, threads included, come from the checkpoint).
  srun --mpi=pmix jsatlas fit --resume "$dir"
else
  srun --mpi=pmix jsatlas fit --list "$list" -o "$dir" --threads "$threads" --iters 20000 --checkpoint-every 500
fi
