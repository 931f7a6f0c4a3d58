#!/usr/bin/env bash
# A furrow sweep over several nodes of a Slurm cluster: one MPI rank per task, each rank running
# one run at a time on its task's cores; rank 0 writes DIR/sweep.csv, sweep.json and sweep.png.
# Submit from the repository root (furrow built in build/, DIR on a file system every node sees):
#   sbatch assets/slurm_sweep.sh
# Resubmitting the same script after a time-out or a scancel finishes only the missing runs.
#SBATCH --job-name=furrow-sweep
#SBATCH --nodes=4
#SBATCH --ntasks-per-node=8
#SBATCH --cpus-per-task=4
#SBATCH --time=12:00:00
#SBATCH --output=furrow-sweep-%j.log
set -euo pipefail

scene=scenes/two_plates.json
out=out/two_plates_sweep

# srun starts the ranks through Slurm's PMI (PMIx with Open MPI 4: --mpi=pmix); `mpirun` works
# too inside the allocation. --threads matches the cores Slurm gave each task.
srun --mpi=pmix build/furrow sweep "$scene" \
  --vary bodies.plate_right.start_m.0=0.63:0.93:0.02 \
  --vary domain.dx_m=0.005,0.0025 \
  --threads "${SLURM_CPUS_PER_TASK:-1}" \
  --out "$out" --quiet
