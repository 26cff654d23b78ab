#!/usr/bin/env bash
# Slurm: one CCO tree grown in parts by domain decomposition ([tree] parts = K, after Cury et al.
# 2021), one array task per part, then one job that joins them into the sample:
#   job=$(sbatch --parsable --array=0-7 examples/cluster/slurm_cco_parts.sh)
#   sbatch --dependency=afterok:$job --wrap "angiosynth generate $PARAMS --out $OUT --join"
# The array's size is [tree] parts (0-7 for 8). Every task first grows the same trunk (a second or
# so), then its own part, and writes OUT.parts/part_0000I.ccopart whole or not at all; a requeued
# task whose part is there already keeps it. The parameter file must fix the seed (or pass --seed
# to every task and to the join). The join solves the whole tree's physics, checks every vessel
# against every other, and writes the sample; `angiosynth rasterize` then writes volumes larger
# than memory (examples/cluster/slurm_rasterize.sh). bench/run_cco_parts_slurm.sh runs this on a
# one-node Slurm (scripts/local_slurm.sh).
#SBATCH --job-name=angiosynth-cco-parts
#SBATCH --array=0-7
#SBATCH --cpus-per-task=1
#SBATCH --mem=2G
#SBATCH --time=01:00:00
#SBATCH --requeue
set -euo pipefail
PARAMS=${PARAMS:-examples/cco_organ_parts_3d.toml}
OUT=${OUT:?the sample directory the join will write}
angiosynth generate "$PARAMS" --out "$OUT" --part "$SLURM_ARRAY_TASK_ID" --threads "$SLURM_CPUS_PER_TASK"
