#!/usr/bin/env bash
# `angiosynth segment` against scikit-image on one 256³ image (target: Frangi at least 20× faster
# on 2 cores, responses correlated ≥ 0.99): the 4000-terminal CCO sphere imaged on 256³ voxels
# with the cta profile; Frangi and Sato at σ 1, 2, 3 voxels, each timed in the program and in
# scikit-image (Debian's python3-skimage), and the responses compared.
#   bash bench/run_segment.sh [WORK_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
work=${1:-$(mktemp -d)}
mkdir -p "$work"
source bench/sphere_256.sh
sphere256 "$work"
build/angiosynth generate "$work/sphere_256.toml" --out "$work/sample" --profile cta --force --quiet
sigmas=0.225,0.45,0.675
for method in frangi sato; do
  /usr/bin/time -f "$method (angiosynth): %e s wall, %M KB peak" build/angiosynth segment "$work/sample/image_cta.nii.gz" \
    --method "$method" --sigmas "$sigmas" --out "$work/$method.nii.gz" --response "$work/${method}_response.nii.gz" --force
done
/usr/bin/python3 - "$work" <<'PY'
import sys, time
import nibabel as nib, numpy as np
from skimage.filters import frangi, sato
w = sys.argv[1]
a = np.asanyarray(nib.load(f"{w}/sample/image_cta.nii.gz").dataobj).astype(np.float32)
print("image", a.shape)
# The program repeats the border voxel (scikit-image's mode "nearest"); scikit-image's default
# reflects, which differs within the largest kernel's reach of the faces only.
for mode in ("nearest", "reflect"):
    for name, f in [("frangi", lambda: frangi(a, sigmas=[1, 2, 3], alpha=0.5, beta=0.5, gamma=15, black_ridges=False, mode=mode)),
                    ("sato", lambda: sato(a, sigmas=[1, 2, 3], black_ridges=False, mode=mode))]:
        t = time.perf_counter()
        ref = f()
        seconds = time.perf_counter() - t
        ours = np.asanyarray(nib.load(f"{w}/{name}_response.nii.gz").dataobj)
        inner = (slice(12, -12),) * 3
        print(f"{name} (scikit-image, mode {mode}): {seconds:.1f} s; correlation with angiosynth's response "
              f"{np.corrcoef(ours.ravel(), ref.ravel())[0, 1]:.8f}, 12 voxels from the faces {np.corrcoef(ours[inner].ravel(), ref[inner].ravel())[0, 1]:.8f}")
PY
