#!/usr/bin/env bash
# Slurm: one volume larger than memory, rasterised by an array of tasks into one OME-Zarr store.
# Each task writes its own contiguous range of chunks (memory: a few chunks per task, not the
# volume); a requeued or killed task resumes after its last finished batch. When every task has
# finished, one job builds the multiscale pyramid:
#   job=$(sbatch --parsable examples/cluster/slurm_rasterize.sh)
#   sbatch --dependency=afterok:$job --wrap "angiosynth rasterize $SAMPLE --out $STORE --voxel-size $VOXEL --tasks 16 --pyramid"
# The array's size is the number of tasks (sbatch --array=0-3 for 4). Every task, and the pyramid
# job, names the same sample, voxel size and --tasks: the store's job record refuses a task of
# another job. bench/run_zarr_slurm.sh runs this on a one-node Slurm (scripts/local_slurm.sh).
#SBATCH --job-name=angiosynth-rasterize
#SBATCH --array=0-15
#SBATCH --cpus-per-task=2
#SBATCH --mem=2G
#SBATCH --time=02:00:00
#SBATCH --requeue
set -euo pipefail
SAMPLE=${SAMPLE:?a sample directory angiosynth generate wrote}
STORE=${STORE:-$SAMPLE.ome.zarr}
VOXEL=${VOXEL:?the voxel edge in mm, e.g. 0.005}
angiosynth rasterize "$SAMPLE" --out "$STORE" --voxel-size "$VOXEL" --tasks "$SLURM_ARRAY_TASK_COUNT" --task "$SLURM_ARRAY_TASK_ID" \
  --threads "$SLURM_CPUS_PER_TASK" --quiet
