#!/usr/bin/env bash
# Slurm: one array task per shard; every task writes its own manifest part, then one job merges.
#   sbatch examples/cluster/slurm_array.sh
#   sbatch --dependency=afterok:<array job id> --wrap "angiosynth dataset finalize $OUT/Dataset911_VesselCTA"
#SBATCH --job-name=angiosynth
#SBATCH --array=0-19
#SBATCH --cpus-per-task=2
#SBATCH --mem=4G
#SBATCH --time=01:00:00
set -euo pipefail
OUT=${OUT:-$HOME/nnUNet_raw}
# --shard auto/20 takes K from SLURM_ARRAY_TASK_ID; --resume makes a requeued task skip what verifies.
angiosynth dataset examples/dataset_large.toml --out "$OUT" --shard auto/20 --resume --threads "$SLURM_CPUS_PER_TASK"
