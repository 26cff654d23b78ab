#!/usr/bin/env bash
# Cross-validation scoring, the worked example of docs/scoring.md: the artery-vein dataset, a
# stand-in segmenter's predictions (examples/threshold_dataset.py) and a 5-fold split in nnU-Net's
# splits_final.json form; each fold's validation cases scored against the training label and the
# exact mask, with per-class summaries. Prints the page's table.
#   bash examples/score_folds.sh [WORK_DIR]     (needs python3-nibabel and python3-skimage)
#   ANGIOSYNTH=path/to/angiosynth: another build of the program
set -euo pipefail
cd "$(dirname "$0")/.."
work=${1:-out/score_folds}
exe=${ANGIOSYNTH:-build/angiosynth}
mkdir -p "$work"
"$exe" dataset examples/dataset_artery_vein.toml --out "$work/raw" --resume --quiet
ds="$work/raw/Dataset904_ArteryVein"
/usr/bin/python3 examples/threshold_dataset.py "$ds" "$work/pred"
# Case i in fold i mod 5 (nnU-Net draws its own split; the file has its form).
/usr/bin/python3 - "$ds" "$work/splits_final.json" <<'PY'
import json, pathlib, sys
ids = sorted(p.name[:-7] for p in (pathlib.Path(sys.argv[1]) / "labelsTr").glob("*.nii.gz"))
folds = [{"train": [c for i, c in enumerate(ids) if i % 5 != k], "val": [c for i, c in enumerate(ids) if i % 5 == k]} for k in range(5)]
json.dump(folds, open(sys.argv[2], "w"), indent=1)
PY
for k in 0 1 2 3 4; do
  for truth in training exact; do
    "$exe" score --dataset "$ds" --predictions "$work/pred" --splits "$work/splits_final.json" --fold $k --truth $truth \
      --out "$work/fold${k}_$truth.json" --class-csv "$work/fold${k}_${truth}_classes.csv" --force --quiet
  done
done
/usr/bin/python3 - "$work" <<'PY'
import json, sys
print("| fold | cases | Dice, training label | Dice, exact mask | clDice, exact mask | artery recall, exact mask | vein recall, exact mask |")
print("|---|---|---|---|---|---|---|")
for k in range(5):
    t = json.load(open(f"{sys.argv[1]}/fold{k}_training.json"))
    e = json.load(open(f"{sys.argv[1]}/fold{k}_exact.json"))
    c = e["aggregates"]["per_class"]["classes"]
    print(f"| {k} | {e['cases']} | {t['summary']['dice']['mean']:.3f} | {e['summary']['dice']['mean']:.3f} | "
          f"{e['summary']['cldice']['mean']:.3f} | {c['artery']['recall']['mean']:.3f} | {c['vein']['recall']['mean']:.3f} |")
PY
