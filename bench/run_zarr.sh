#!/usr/bin/env bash
# Volumes larger than memory: the CCO sphere rasterised into OME-Zarr at finer voxels, one
# process; time, peak memory and store size per grid (docs/benchmarks.md). The finest grid is
# then written again as a cluster would, by 4 tasks (2 at a time, 1 thread each) with chunks of
# 96 (so the chunk borders move), and python3-zarr compares the two stores on random subvolumes
# and on the coarse levels whole, and checks the channels against each other.
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
v=${voxels[-1]}
tasks="$work/sphere_${v}_tasks.ome.zarr"
for pair in "0 1" "2 3"; do
  for t in $pair; do
    /usr/bin/time -f "task $t: peak RSS %M kB, wall %e s" "$build/angiosynth" rasterize "$work/sphere" --out "$tasks" --voxel-size "$v" \
      --chunk 96 --tasks 4 --task "$t" --threads 1 --quiet &
  done
  wait
done
/usr/bin/time -f "pyramid: peak RSS %M kB, wall %e s" "$build/angiosynth" rasterize "$work/sphere" --out "$tasks" --voxel-size "$v" --chunk 96 --tasks 4 --pyramid --quiet
/usr/bin/python3 - "$work/sphere_$v.ome.zarr" "$tasks" <<'PY'
import sys, numpy as np, zarr
root, other = zarr.open(sys.argv[1], mode='r'), zarr.open(sys.argv[2], mode='r')
n = root['0'].shape
rng = np.random.default_rng(1)
boxes = bad = differ = 0
paths = ['0', 'fraction/0', 'radius/0', 'labels/mask/0', 'labels/centerline/0', 'labels/instances/0', 'labels/classes/0']
while boxes < 12:
    z, y, x = (int(rng.integers(0, s - 160)) for s in n)
    sl = np.s_[z:z + 160, y:y + 160, x:x + 160]
    mask = root['labels/mask/0'][sl]
    if not mask.any(): continue
    boxes += 1
    differ += sum(int((root[p][sl] != other[p][sl]).sum()) for p in paths)
    frac, cl, rad = root['fraction/0'][sl], root['labels/centerline/0'][sl], root['radius/0'][sl]
    inst, cls, img = root['labels/instances/0'][sl], root['labels/classes/0'][sl], root['0'][sl]
    bad += int(np.any((frac >= 0.5) & (mask == 0))) + int(np.any((cl == 1) & (mask == 0))) + int(np.any((rad > 0) != (cl == 1)))
    bad += int(np.any((inst > 0) != (mask == 1))) + int(np.any((cls > 0) != (mask == 1)))
    bad += int(not np.array_equal(img, np.clip(np.round(frac.astype(np.float64) * 255), 0, 255).astype(np.uint8)))
levels = len(root.attrs['multiscales'][0]['datasets'])
for l in range(min(3, levels - 1), levels):
    for p in ('', 'fraction/', 'labels/mask/', 'labels/instances/'):
        differ += int((root[p + str(l)][...] != other[p + str(l)][...]).sum())
print(f"{boxes} subvolumes of 160^3 with vessels: {'channels agree' if bad == 0 else str(bad) + ' disagreements'}; "
      f"{differ} voxels differ between one process (chunks 128) and 4 tasks (chunks 96), levels {min(3, levels - 1)}+ compared whole")
PY
echo "stores in $work (remove when done)"
