#!/usr/bin/env bash
# One long furrow run (the paper's resolution) on a Slurm cluster whose jobs may not last that long.
# Slurm sends SIGTERM two minutes before the time limit; furrow finishes its step, writes a
# checkpoint and exits with status 130; the job then requeues itself and the next job continues
# the run with --resume (a first job with nothing to resume starts the run). Checkpoints are also
# written every 30 minutes, so a node failure loses at most that much.
# Submit from the repository root (furrow built in build/):
#   sbatch assets/slurm_long_run.sh
#SBATCH --job-name=furrow-paper-run
#SBATCH --nodes=1
#SBATCH --ntasks=1
#SBATCH --cpus-per-task=8
#SBATCH --time=02:00:00
#SBATCH --signal=B:TERM@120
#SBATCH --requeue
#SBATCH --open-mode=append
#SBATCH --output=furrow-paper-run-%j.log
set -uo pipefail

scene=scenes/plate_intrusion.json
out=out/plate_intrusion_dx1.25mm

# furrow runs in the background so the batch shell can pass Slurm's SIGTERM on to it
build/furrow run "$scene" --set domain.dx_m=0.00125 --threads "${SLURM_CPUS_PER_TASK:-1}" \
  --out "$out" --resume --checkpoint-every 30 --yes &
pid=$!
trap 'kill -TERM "$pid"' TERM
wait "$pid"; status=$?
# `wait` returns early when the trap fires: wait again for furrow's own exit status
if kill -0 "$pid" 2>/dev/null; then wait "$pid"; status=$?; fi
if [ "$status" -eq 130 ]; then
  scontrol requeue "$SLURM_JOB_ID"
fi
exit "$status"
