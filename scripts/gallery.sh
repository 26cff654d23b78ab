#!/bin/bash
# Makes the pictures of docs/gallery/ from the shipped examples: a maximum-intensity projection of
# each growth method's example, each degradation profile's image beside its truth, a rendering of
# a surface mesh (VTK under xvfb) and a calibre plot of a scored segmentation. The pages of docs/
# show them; rerun it after a change that alters what the examples grow.
# Usage: bash scripts/gallery.sh [BUILD_DIR]   (default build; the program must be built)
set -euo pipefail
cd "$(dirname "$0")/.."
root="$(pwd)"
build="$(cd "${1:-build}" && pwd)"
[ -x "$build/angiosynth" ] || { echo "gallery.sh: $build/angiosynth is not built; run scripts/build.sh first" >&2; exit 2; }
# The checks' own tools: Debian's Python with nibabel, Pillow and VTK, and a virtual display for VTK.
need=()
/usr/bin/python3 -c "import nibabel, PIL, vtk" 2>/dev/null || need+=(python3-nibabel python3-pil python3-vtk9)
command -v xvfb-run >/dev/null || need+=(xvfb xauth)
if [ ${#need[@]} -gt 0 ]; then
  sudo=""; [ "$(id -u)" -ne 0 ] && sudo="sudo"
  $sudo apt-get install -y --no-install-recommends "${need[@]}"
fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
out="$root/docs/gallery"
mkdir -p "$out"
as="$build/angiosynth"

echo "growing the examples"
for ex in vascusynth_like cco_artery_vein_3d dcco_scale_specific_2d colonisation_fig5_2d lsystem_grammar_3d; do
  "$as" generate "examples/$ex.toml" --out "$work/$ex" --no-profiles --quiet
done
"$as" generate examples/cco_sphere_3d.toml --out "$work/profiles" --profile cta,tof_mra,two_photon,domain_randomisation --quiet
"$as" mesh "$work/profiles" --out "$work/mesh" --format vtp --quiet

echo "scoring a thresholded CTA-like image"
/usr/bin/python3 - "$work" <<'EOF'
import sys, nibabel as nib, numpy as np
w = sys.argv[1]
img = nib.load(f"{w}/profiles/image_cta.nii.gz")
a = np.asanyarray(img.dataobj).astype(np.float32)
# A naive segmenter: the voxels brighter than the midpoint of the image's 50th and 99.9th percentiles.
t = 0.5 * (np.percentile(a, 50) + np.percentile(a, 99.9))
nib.save(nib.Nifti1Image((a > t).astype(np.uint8), img.affine), f"{w}/threshold.nii.gz")
EOF
"$as" score "$work/threshold.nii.gz" "$work/profiles" --out "$work/scores.json" --quiet
"$as" plot-calibre "$out/calibre.png" "$work/scores.json" --force

echo "composing the pictures"
/usr/bin/python3 - "$work" "$out" <<'EOF'
import os, sys
from PIL import Image, ImageDraw
w, out = sys.argv[1], sys.argv[2]

def mip(sample, suffix=""):
    # The projection with the most to show: the largest of the three.
    files = [f"{w}/{sample}/mip_{a}{suffix}.png" for a in "xyz"]
    best = max((f for f in files if os.path.exists(f)), key=lambda f: Image.open(f).size[0] * Image.open(f).size[1])
    return Image.open(best).convert("RGB")

def small(im, width=320):
    return im.resize((width, max(1, round(im.size[1] * width / im.size[0]))), Image.LANCZOS)

def labelled(im, text):
    canvas = Image.new("RGB", (im.size[0], im.size[1] + 22), "white")
    canvas.paste(im, (0, 22))
    ImageDraw.Draw(canvas).text((6, 4), text, fill="black")
    return canvas

for sample, name in [("vascusynth_like", "vascusynth"), ("cco_artery_vein_3d", "cco"), ("dcco_scale_specific_2d", "dcco"),
                     ("colonisation_fig5_2d", "colonisation"), ("lsystem_grammar_3d", "lsystem")]:
    small(mip(sample)).save(f"{out}/method_{name}.png", optimize=True)
truth = small(mip("profiles"), 240)
for profile in ["cta", "tof_mra", "two_photon", "domain_randomisation"]:
    pair = Image.new("RGB", (480, truth.size[1] + 22), "white")
    pair.paste(labelled(truth, "truth"), (0, 0))
    pair.paste(labelled(small(mip("profiles", "_" + profile), 240), profile), (240, 0))
    pair.save(f"{out}/profile_{profile}.png", optimize=True)
EOF

echo "rendering the surface mesh"
xvfb-run -a /usr/bin/python3 - "$work/mesh/surface.vtp" "$out/mesh.png" <<'EOF'
import sys, vtk
reader = vtk.vtkXMLPolyDataReader()
reader.SetFileName(sys.argv[1])
normals = vtk.vtkPolyDataNormals()
normals.SetInputConnection(reader.GetOutputPort())
mapper = vtk.vtkPolyDataMapper()
mapper.SetInputConnection(normals.GetOutputPort())
mapper.ScalarVisibilityOff()
actor = vtk.vtkActor()
actor.SetMapper(mapper)
actor.GetProperty().SetColor(0.80, 0.25, 0.22)
renderer = vtk.vtkRenderer()
renderer.AddActor(actor)
renderer.SetBackground(1, 1, 1)
renderer.ResetCamera()
renderer.GetActiveCamera().Zoom(1.4)
window = vtk.vtkRenderWindow()
window.SetOffScreenRendering(1)
window.AddRenderer(renderer)
window.SetSize(480, 480)
window.Render()
grab = vtk.vtkWindowToImageFilter()
grab.SetInput(window)
writer = vtk.vtkPNGWriter()
writer.SetFileName(sys.argv[2])
writer.SetInputConnection(grab.GetOutputPort())
writer.Write()
EOF
ls -la "$out"
