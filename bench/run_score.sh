#!/usr/bin/env bash
# Time of `angiosynth score` on one 256³ case (target: every metric within 3 s on 2 cores): the
# 4000-terminal CCO sphere imaged on 256³ voxels, scored with its clean image (every voxel with
# some partial volume) as the prediction.
#   bash bench/run_score.sh [WORK_DIR]          (SCORE_DATASET=1: also the 200-case dataset)
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

# A 200-case 128³ dataset (bench/dataset_200_128.toml, cta) scored with every metric (target:
# <= 2 min on 2 cores), its degraded images thresholded at 150 HU as the predictions.
if [ -n "${SCORE_DATASET:-}" ]; then
  build/angiosynth dataset bench/dataset_200_128.toml --out "$work/ds" --quiet
  ds="$work/ds/Dataset990_VesselBench"
  /usr/bin/python3 - "$ds" "$work/pred" <<'PY'
import glob, os, sys, nibabel as nib, numpy as np
ds, out = sys.argv[1], sys.argv[2]
os.makedirs(out, exist_ok=True)
for f in sorted(glob.glob(ds + '/imagesTr/*_0000.nii.gz')):
    img = nib.load(f)
    nib.save(nib.Nifti1Image((np.asarray(img.dataobj) > 150).astype(np.uint8), img.affine), out + '/' + os.path.basename(f)[:-12] + '.nii.gz')
PY
  /usr/bin/time -f "score --dataset: %e s wall, %M KB peak" build/angiosynth score --dataset "$ds" --predictions "$work/pred" \
    --out "$work/dataset_scores.json" --csv "$work/dataset_scores.csv" --force --quiet
  tail -3 "$work/dataset_scores.csv" | cut -c1-120
fi
