#!/usr/bin/env bash
# Time of `angiosynth score` on one 256³ case (target: every metric within 3 s on 2 cores): the
# 4000-terminal CCO sphere imaged on 256³ voxels, scored with its clean image's voxels > 0 (every
# voxel with some partial volume) as the prediction (the 8-bit image itself would be read as labels).
#   bash bench/run_score.sh [WORK_DIR]          (SCORE_DATASET=1: also the 200-case dataset; SCORE_CLASSES=1: per-class scoring)
set -euo pipefail
cd "$(dirname "$0")/.."
work=${1:-$(mktemp -d)}
mkdir -p "$work"
source bench/sphere_256.sh
sphere256 "$work"
build/angiosynth generate "$work/sphere_256.toml" --out "$work/sample" --no-profiles --force --quiet
python3 -c "import json; print('image', json.load(open('$work/sample/sample.json'))['statistics']['image_size'])"
/usr/bin/python3 -c "
import nibabel as nib, numpy as np
i = nib.load('$work/sample/image.nii.gz')
nib.save(nib.Nifti1Image((np.asarray(i.dataobj) > 0).astype(np.uint8), i.affine), '$work/touched.nii.gz')"
for i in 1 2 3; do
  /usr/bin/time -f "score: %e s wall, %M KB peak" build/angiosynth score "$work/touched.nii.gz" "$work/sample" \
    --out "$work/scores_$i.json" --force --quiet
done

# Per-class scoring on 256³: the artery-vein example's classes shifted by a voxel as a labelled
# prediction (2 classes, --topcow), and its vessels numbered into 40 classes (instance mod 40,
# the prediction shifted alike) under TopBrain's 40-class scheme: the cost per class.
if [ -n "${SCORE_CLASSES:-}" ]; then
  sed -e 's|^voxel_size = "0.3 mm".*|voxel_size = "0.225 mm"|' -e 's|^formats = .*|formats = ["nifti"]|' \
      examples/cco_artery_vein_3d.toml > "$work/av_256.toml"
  build/angiosynth generate "$work/av_256.toml" --out "$work/av" --no-profiles --force --quiet
  /usr/bin/python3 - "$work" <<'PY'
import sys, nibabel as nib, numpy as np
w = sys.argv[1]
c = nib.load(w + '/av/classes.nii.gz'); cls = np.asarray(c.dataobj).astype(np.uint8)
inst = np.asarray(nib.load(w + '/av/instances.nii.gz').dataobj)
many = np.where(cls > 0, inst % 40 + 1, 0).astype(np.uint8)
for name, v in (('classes2', cls), ('classes40', many)):
    shifted = np.zeros_like(v); shifted[1:] = v[:-1]
    nib.save(nib.Nifti1Image(v, c.affine), f'{w}/{name}_truth.nii.gz')
    nib.save(nib.Nifti1Image(shifted, c.affine), f'{w}/{name}_pred.nii.gz')
print('image', cls.shape, 'classes present', len(np.unique(many)) - 1)
PY
  /usr/bin/time -f "score, 2 classes: %e s wall, %M KB peak" build/angiosynth score "$work/classes2_pred.nii.gz" "$work/av" \
    --topcow --out "$work/classes2.json" --force --quiet
  /usr/bin/time -f "score, 40 classes (topbrain2025-ct): %e s wall, %M KB peak" build/angiosynth score "$work/classes40_pred.nii.gz" \
    "$work/classes40_truth.nii.gz" --label-scheme topbrain2025-ct --topcow --out "$work/classes40.json" --force --quiet
fi

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
