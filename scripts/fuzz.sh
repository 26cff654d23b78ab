#!/usr/bin/env bash
# Runs every libFuzzer target of build-san/ for SECONDS each (default 20), as many at a time as there
# are cores (each target is one process on one core), seeded from the shipped examples, profiles,
# maps and test data. A crash, sanitizer report, internal error (an exception other than a
# file:line input error), time-out (10 s per case) or allocation over 2 GiB stops that target with
# the case saved in build-san/fuzz-findings/, and the run fails once every target has finished.
#   bash scripts/fuzz.sh [SECONDS] [TARGET...]      e.g. bash scripts/fuzz.sh 3600 fuzz_profile
#   FUZZ_RUNS=100000 bash scripts/fuzz.sh 7200       stop each target after 100000 cases (SECONDS caps it)
#   FUZZ_SEED=0 …                                    a random seed (default 1: CI explores the same cases every run)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-20}
shift || true
[ "$seconds" -gt 0 ] || exit 0
root=$(pwd)
corpus=build-san/fuzz-corpus
findings=build-san/fuzz-findings
mkdir -p "$findings"
for t in toml_params vascusynth_params box_map noise_file profile dataset_spec manifest nifti_mask network_file \
         graph_mesh initial_network method_params mesh_options score plot_calibre morphometry_reference zarr_chunk; do mkdir -p "$corpus/fuzz_$t"; done
cp examples/*.toml "$corpus/fuzz_toml_params/" 2>/dev/null || true
for f in examples/vascusynth/param*.txt; do cp "$f" "$corpus/fuzz_vascusynth_params/"; done
for f in demand_maps/vascusynth_rods_100.txt demand_maps/supply_100.txt tests/data/*.txt; do [ -f "$f" ] && cp "$f" "$corpus/fuzz_box_map/" || true; done
for f in noise_profiles/*.txt tests/data/*noise*; do [ -f "$f" ] && cp "$f" "$corpus/fuzz_noise_file/" || true; done
cp noise_profiles/*.toml "$corpus/fuzz_profile/"
cp examples/*.swc examples/*.cco tests/data/network/*.vtp "$corpus/fuzz_network_file/" 2>/dev/null || true
# Graphs for mesh and [initial]: the shipped networks (the initial-network target's first byte
# picks the method: even DCCO, odd colonisation).
cp examples/*.swc examples/*.cco tests/data/network/*.vtp "$corpus/fuzz_graph_mesh/" 2>/dev/null || true
for f in examples/*.swc tests/data/network/*.vtp; do
  { printf 'D'; cat "$f"; } > "$corpus/fuzz_initial_network/dcco_$(basename "$f")"
  { printf 'C'; cat "$f"; } > "$corpus/fuzz_initial_network/colonisation_$(basename "$f")"
done
# Method parameters: the first byte picks the method (its value mod 5), the rest is a fragment of
# keys; the shipped examples' tables are the fragments.
for f in examples/*.toml; do
  for m in 0 1 2 3 4; do { printf "\\x3$m"; grep -v '^\s*\(demand_map\|file\|mask\) *=' "$f"; } > "$corpus/fuzz_method_params/$m-$(basename "$f")"; done
done
# Mesh options: the [mesh] tables of the parameter reference and a few hand-made ones.
printf 'ends = "capped"\nflow_extension = 2\nremesh = true\n' > "$corpus/fuzz_mesh_options/capped.toml"
printf 'wall_from_graph = true\nends = "open"\nclip_box = [1, -2, -2, 8, 2, 2]\n' > "$corpus/fuzz_mesh_options/wall.toml"
printf 'method = "contour"\ndecimate = true\nmax_error = 0.2\nsamples_across = 2\n' > "$corpus/fuzz_mesh_options/contour.toml"
printf 'junctions = "tetrahedra"\nsliver_angle = 12\nmax_angle = 100\nring_spacing = 3\nvoxel_size = "0.1 mm"\n' > "$corpus/fuzz_mesh_options/tetra.toml"
# Score results for plot-calibre: one case and a dataset.
printf '%s' '{"calibre":[{"radius_voxels":[0,0.5],"recall":0.2},{"radius_voxels":[0.5,1],"recall":0.6},{"radius_voxels":[1,null],"recall":null}]}' \
  > "$corpus/fuzz_plot_calibre/case.json"
printf '%s' '{"per_case":[{"calibre":[{"radius_voxels":[0,1],"recall":0.5}]},{"calibre":[{"radius_voxels":[0,1],"recall":1}]}]}' \
  > "$corpus/fuzz_plot_calibre/dataset.json"
# Morphometry references: the shipped files (first byte 0: a file) and a stats CSV (1: a directory).
for f in data/morphometry/*.toml; do { printf '0'; cat "$f"; } > "$corpus/fuzz_morphometry_reference/$(basename "$f")"; done
printf '1tree,parent,r_parent_mm,asymmetry,area_ratio,murray_exponent,radius_mm\n0,1,0.5,0.8,1.2,2.9,0.4\n0,2,0.2,0.5,1.1,3.1,0.1\n' \
  > "$corpus/fuzz_morphometry_reference/stats.csv"
# Zarr chunks: a float chunk of 8^3 by numcodecs, Blosc (first byte 8) and zlib (9).
/usr/bin/python3 - "$corpus/fuzz_zarr_chunk" <<'PY'
import sys, numpy as np, numcodecs
v = np.linspace(0, 1, 512, dtype='<f4').tobytes()
open(sys.argv[1] + '/blosc_f32', 'wb').write(b'\x08' + numcodecs.Blosc(cname='lz4', clevel=5, shuffle=1).encode(v))
open(sys.argv[1] + '/zlib_f32', 'wb').write(b'\x09' + numcodecs.Zlib(level=5).encode(v))
PY
# Predictions (fuzz_score): the target writes its sample's own mask into its corpus on start.
for f in examples/dataset_*.toml tests/data/dataset_*.toml; do cp "$f" "$corpus/fuzz_dataset_spec/"; done
printf '%s\n' '{"index":0,"status":"ok","files":[{"path":"imagesTr/F_0000_0000.nii.gz","size":5,"sha256":"6105d6cc76af400325e94d588ce511be5bfdbb73b437dc51eca43917d7a43e3d"}]}' \
  '{"index":1,"status":"failed","error":"x"}' > "$corpus/fuzz_manifest/two_lines.jsonl"
if [ ! -f "$corpus/fuzz_nifti_mask/ball8.nii" ]; then  # an 8^3 ball, 0.5 mm voxels, by nibabel
  /usr/bin/python3 - "$corpus/fuzz_nifti_mask/ball8.nii" <<'PY'
import sys, numpy as np, nibabel as nib
i, j, k = np.mgrid[:8, :8, :8]
m = (((i - 3.5) ** 2 + (j - 3.5) ** 2 + (k - 3.5) ** 2) < 12).astype(np.uint8)
nib.save(nib.Nifti1Image(m, np.diag([0.5, 0.5, 0.5, 1])), sys.argv[1])
PY
fi
# Inputs that once failed, kept so every run tries them first.
for d in fuzz/regressions/*/; do cp "$d"* "$corpus/$(basename "$d")/" 2>/dev/null || true; done
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(fuzz_toml_params fuzz_vascusynth_params fuzz_box_map fuzz_noise_file fuzz_profile fuzz_dataset_spec fuzz_manifest fuzz_nifti_mask fuzz_network_file
                                     fuzz_graph_mesh fuzz_initial_network fuzz_method_params fuzz_mesh_options fuzz_score fuzz_plot_calibre
                                     fuzz_morphometry_reference fuzz_zarr_chunk)
export ASAN_OPTIONS="detect_leaks=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:suppressions=$root/sanitizer/ubsan.supp"
# Targets run $(nproc) at a time: each is one process on one core.
fuzz_one() {
  local t=$1 work runs run_limit=()
  work=$(mktemp -d)
  [ -n "${FUZZ_RUNS:-}" ] && run_limit=(-runs="$FUZZ_RUNS")
  local ok=1
  (cd "$work" && "$root/build-san/$t" -max_total_time="$seconds" "${run_limit[@]}" -seed="${FUZZ_SEED:-1}" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=2048 \
      -artifact_prefix="$root/$findings/$t-" -print_final_stats=1 "$root/$corpus/$t" >"$work/log" 2>&1) || ok=0
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$work/log" | grep -o '[0-9]*$' || echo 0)
  if [ "$ok" = 0 ]; then
    { echo "$t: FAILED after $runs cases"; tail -n 40 "$work/log"; } >&2
    rm -rf "$work"
    touch "$marks/$t"
    return 1
  fi
  echo "$t: $runs cases in $(grep -o 'Done [0-9]* runs in [0-9]* second' "$work/log" | grep -o 'in [0-9]* second' | grep -o '[0-9]*' || echo "$seconds") s, 0 crashes, 0 sanitizer reports, 0 internal errors, 0 time-outs"
  rm -rf "$work"
}
lanes=$(nproc)
marks=$(mktemp -d)  # one file per failed target
for t in "${targets[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$lanes" ]; do wait -n || true; done
  fuzz_one "$t" &
done
wait
failed=$(find "$marks" -type f | wc -l)
rm -rf "$marks"
if [ "$failed" -gt 0 ]; then
  echo "fuzz: $failed of ${#targets[@]} failed (cases in $findings/)"
  exit 1
fi
echo "fuzz: ${#targets[@]} passed, 0 failed"
