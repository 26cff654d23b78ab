#!/usr/bin/env bash
# The CCO sphere rasterised into OME-Zarr by a real Slurm array (examples/cluster/slurm_rasterize.sh)
# and its pyramid job, then by one process: wall time of each and whether every file of the two
# stores is byte-identical (the job records and progress files apart). Needs sbatch; on one
# machine, scripts/local_slurm.sh makes a one-node Slurm.
#   bash bench/run_zarr_slurm.sh [BUILD_DIR] [VOXEL_MM] [TASKS] [CPUS_PER_TASK]   (default build 0.028125 4 1)
set -euo pipefail
build=$(cd "${1:-build}" && pwd); v=${2:-0.028125}; tasks=${3:-4}; cpus=${4:-1}
command -v sbatch >/dev/null || { echo "run_zarr_slurm.sh: no sbatch (scripts/local_slurm.sh sets up a one-node Slurm)" >&2; exit 1; }
work=$(mktemp -d -t angiosynth_zarr_slurm_XXXX)
"$build/angiosynth" generate examples/cco_sphere_3d.toml --out "$work/sphere" --format png --quiet
store="$work/slurm.ome.zarr"
t0=$(date +%s.%N)
job=$(sbatch --parsable --array=0-$((tasks - 1)) --cpus-per-task="$cpus" --mem=1G -o "$work/task_%a.log" \
  --export=ALL,PATH="$build:$PATH",SAMPLE="$work/sphere",STORE="$store",VOXEL="$v" examples/cluster/slurm_rasterize.sh)
sbatch --wait --parsable --dependency=afterok:"$job" --cpus-per-task="$cpus" --mem=1G -o "$work/pyramid.log" \
  --wrap "$build/angiosynth rasterize $work/sphere --out $store --voxel-size $v --tasks $tasks --pyramid --threads $cpus --quiet" >/dev/null
t1=$(date +%s.%N)
/usr/bin/time -f "one process: peak RSS %M kB, wall %e s" "$build/angiosynth" rasterize "$work/sphere" --out "$work/one.ome.zarr" --voxel-size "$v" --quiet
files=$(cd "$store" && find . -type f -not -path './.angiosynth/*' | wc -l)
if diff -rq --exclude=.angiosynth "$store" "$work/one.ome.zarr" >/dev/null; then same="byte-identical"; else same="DIFFERENT"; fi
printf "slurm: %d array tasks (%d CPU each) and the pyramid job: %s s wall; %s files, %s to one process's store\n" \
  "$tasks" "$cpus" "$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }')" "$files" "$same"
echo "stores in $work (remove when done)"
[ "$same" = byte-identical ]
