#!/usr/bin/env bash
# Wall time and peak memory of each stage of the pipeline through the command line, for one or
# more builds of angiosynth (to compare a change against the commit before it):
#   bash bench/run_pipeline.sh [RUNS] BIN [BIN ...]
# Stages: growth with volumes and two profiles (the 4000-terminal CCO sphere, cta and tof_mra),
# the VascuSynth-style example, an 8-sample nnU-Net dataset, the tube surface of the sphere's
# tree, and the scores of its clean image. Each stage runs RUNS times (default 3) per build,
# builds alternating; the fastest run is printed.
set -euo pipefail
cd "$(dirname "$0")/.."
runs=3
if [[ "${1:-}" =~ ^[0-9]+$ ]]; then runs=$1; shift; fi
[ $# -ge 1 ] || { echo "usage: $0 [RUNS] BIN [BIN ...]" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sed -e 's|^formats = .*|formats = ["nifti"]|' examples/cco_sphere_3d.toml > "$work/sphere.toml"
declare -A best_time best_mem
run() {  # label bin args...
  local label=$1 bin=$2; shift 2
  local out="$work/out_$RANDOM"
  local args=("${@//\{OUT\}/$out}")
  /usr/bin/time -o "$work/time" -f "%e %M" "$bin" "${args[@]}" --quiet >/dev/null 2>"$work/stderr" ||
    { echo "$label failed:" >&2; cat "$work/stderr" >&2; exit 1; }
  local t
  t=$(tail -1 "$work/time")
  rm -rf "$out" "$out.json"
  local s=${t% *} m=${t#* }
  if [ -z "${best_time[$label]:-}" ] || awk "BEGIN{exit !($s < ${best_time[$label]})}"; then best_time[$label]=$s; fi
  if [ -z "${best_mem[$label]:-}" ] || [ "$m" -lt "${best_mem[$label]}" ]; then best_mem[$label]=$m; fi
}
# Inputs every build reads the same way: a sample and its graphs, grown once by the first build.
"$1" generate "$work/sphere.toml" --out "$work/sample" --no-profiles --quiet
stages=(generate vascusynth_like dataset mesh score)
for ((r = 0; r < runs; ++r)); do
  for bin in "$@"; do
    run "generate|$bin" "$bin" generate "$work/sphere.toml" --out "{OUT}" --profile cta,tof_mra
    run "vascusynth_like|$bin" "$bin" generate examples/vascusynth_like.toml --out "{OUT}"
    run "dataset|$bin" "$bin" dataset examples/dataset_small.toml --out "{OUT}"
    run "mesh|$bin" "$bin" mesh "$work/sample" --out "{OUT}"
    run "score|$bin" "$bin" score "$work/sample/image.nii.gz" "$work/sample" --out "{OUT}.json"
  done
done
printf '| stage |'; for bin in "$@"; do printf ' %s |' "$bin"; done; printf '\n|---|'; for bin in "$@"; do printf -- '---|'; done; printf '\n'
for s in "${stages[@]}"; do
  printf '| %s |' "$s"
  for bin in "$@"; do printf ' %s s, %s MB |' "${best_time[$s|$bin]}" "$(( ${best_mem[$s|$bin]} / 1024 ))"; done
  printf '\n'
done
