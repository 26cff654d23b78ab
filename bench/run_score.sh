#!/usr/bin/env bash
# Time of `angiosynth score` on one 256³ case (issue 16: every metric <= 3 s on 2 cores): the
# 4000-terminal CCO sphere imaged on 256³ voxels, scored with its clean image (every voxel with
# some partial volume) as the prediction.
#   bash bench/run_score.sh [WORK_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
work=${1:-$(mktemp -d)}
mkdir -p "$work"
sed -e 's|^voxel_size = "0.3 mm".*|voxel_size = "0.2250 mm"|' -e 's|^formats = .*|formats = ["nifti"]|' \
    examples/cco_sphere_3d.toml > "$work/sphere_256.toml"
build/angiosynth generate "$work/sphere_256.toml" --out "$work/sample" --no-profiles --force --quiet
python3 -c "import json; print('image', json.load(open('$work/sample/sample.json'))['statistics']['image_size'])"
for i in 1 2 3; do
  /usr/bin/time -f "score: %e s wall, %M KB peak" build/angiosynth score "$work/sample/image.nii.gz" "$work/sample" \
    --out "$work/scores_$i.json" --force --quiet
done
