#!/usr/bin/env bash
# The scoring worked example of docs/scoring.md: a degraded CTA-like image thresholded at three levels,
# each threshold scored against the exact truth, and the three calibre curves drawn into one PNG.
# Prints the page's table (the test suite checks that the page holds it).
#   bash examples/score_thresholds.sh [WORK_DIR]     (after scripts/example.sh; needs python3-nibabel)
#   ANGIOSYNTH=path/to/angiosynth: another build of the program
set -euo pipefail
cd "$(dirname "$0")/.."
work=${1:-out/score_thresholds}
exe=${ANGIOSYNTH:-build/angiosynth}
mkdir -p "$work"
"$exe" generate examples/vascusynth_like.toml --out "$work/sample" --profile cta --force --quiet
for t in 150 200 250; do
  /usr/bin/python3 - "$work" "$t" <<'PY'
import sys, nibabel as nib, numpy as np
work, t = sys.argv[1], float(sys.argv[2])
img = nib.load(work + '/sample/image_cta.nii.gz')
pred = (np.asarray(img.dataobj) > t).astype(np.uint8)
nib.save(nib.Nifti1Image(pred, img.affine), '%s/threshold_%d.nii.gz' % (work, t))
PY
  "$exe" score "$work/threshold_$t.nii.gz" "$work/sample" --out "$work/scores_$t.json" --csv "$work/scores_$t.csv" --force
done
"$exe" plot-calibre "$work/calibre.png" "$work/scores_150.json" "$work/scores_200.json" "$work/scores_250.json" --labels "150 HU,200 HU,250 HU" --force
/usr/bin/python3 - "$work" <<'PY'
import json, sys
print("| threshold | Dice | precision | recall | HD95 (mm) | centreline recall | clDice |")
print("|---|---|---|---|---|---|---|")
for t in (150, 200, 250):
    j = json.load(open(f"{sys.argv[1]}/scores_{t}.json"))
    o = j["overlap"]
    print(f"| {t} HU | {o['dice']:.3f} | {o['precision']:.3f} | {o['recall']:.3f} | {j['surface']['hd95_mm']:.2f} | "
          f"{j['centreline']['recall']:.3f} | {j['cldice']['skeletons']['cldice']:.3f} |")
PY
