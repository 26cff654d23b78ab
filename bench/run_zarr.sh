#!/usr/bin/env bash
# Volumes larger than memory: the CCO sphere rasterised into OME-Zarr at finer voxels, one
# process; time, peak memory and store size per grid (docs/benchmarks.md). Then python3-zarr
# reads the largest store back and checks its channels agree on random subvolumes.
#   bash bench/run_zarr.sh [BUILD_DIR] [VOXEL_MM ...]     (default: 0.05625 0.0140625)
set -euo pipefail
build=${1:-build}; shift || true
voxels=("$@"); [ ${#voxels[@]} -eq 0 ] && voxels=(0.05625 0.0140625)
work=$(mktemp -d -t angiosynth_zarr_bench_XXXX)
"$build/angiosynth" generate examples/cco_sphere_3d.toml --out "$work/sphere" --format png --quiet
for v in "${voxels[@]}"; do
  /usr/bin/time -f "peak RSS %M kB, wall %e s" "$build/angiosynth" rasterize "$work/sphere" --out "$work/sphere_$v.ome.zarr" --voxel-size "$v"
  du -sh "$work/sphere_$v.ome.zarr"
done
/usr/bin/python3 - "$work/sphere_${voxels[-1]}.ome.zarr" <<'PY'
import sys, numpy as np, zarr
root = zarr.open(sys.argv[1], mode='r')
n = root['0'].shape
rng = np.random.default_rng(1)
boxes = bad = 0
while boxes < 8:
    z, y, x = (int(rng.integers(0, s - 96)) for s in n)
    sl = np.s_[z:z + 96, y:y + 96, x:x + 96]
    mask = root['labels/mask/0'][sl]
    if not mask.any(): continue
    boxes += 1
    frac, cl, rad = root['fraction/0'][sl], root['labels/centerline/0'][sl], root['radius/0'][sl]
    inst, cls, img = root['labels/instances/0'][sl], root['labels/classes/0'][sl], root['0'][sl]
    bad += int(np.any((frac >= 0.5) & (mask == 0))) + int(np.any((cl == 1) & (mask == 0))) + int(np.any((rad > 0) != (cl == 1)))
    bad += int(np.any((inst > 0) != (mask == 1))) + int(np.any((cls > 0) != (mask == 1)))
    bad += int(not np.array_equal(img, np.clip(np.round(frac.astype(np.float64) * 255), 0, 255).astype(np.uint8)))
print(f"{boxes} subvolumes of 96^3 with vessels: {'channels agree' if bad == 0 else str(bad) + ' disagreements'}")
PY
echo "stores in $work (remove when done)"
