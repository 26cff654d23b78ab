#!/bin/bash
# Makes the pictures of docs/gallery/ from the shipped examples: a maximum-intensity projection of
# each growth method's example, each degradation profile's and each effect's image (a slice and a
# projection) beside its truth, a rendering of
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
"$as" generate examples/cco_sphere_3d.toml --out "$work/profiles" --profile cta,tof_mra,two_photon,octa,vascusynth,domain_randomisation --quiet

echo "applying each effect alone"
# Each effect on VascuSynth's example (100³, 0.4 mm) with values that show it, vessels at 300 over
# tissue at 40, no noise unless the effect is noise.
declare -A effect=(
  [gaussian]='sigma = "0.1 contrast"' [uniform]=$'low = "-0.15 contrast"\nhigh = "0.15 contrast"'
  [impulse]=$'salt_probability = 0.01\npepper_probability = 0.01' [rician]='sigma = "0.1 contrast"' [poisson]='photons_per_unit = 0.1'
  [blur]='sigma = "1.5 voxel"' [dropout]=$'count = 20\nlength = "6 voxel"' [shadow]='count = 5' [bias]='amplitude = 0.4'
  [contrast]='gamma = 2' [texture]='amplitude = "0.1 contrast"' [attenuation]='length = "0.5 fov"' [warp]='max_displacement = "0.05 fov"'
  [gibbs]=$'keep_x = 0.3\nkeep_y = 0.3\nkeep_z = 0.3' [kspace_spike]=$'kx = 8\nky = 5\namplitude = 0.01' [motion_ghost]=$'period = 8\namplitude = 0.5'
  [undersample]='factor = 2' [partial_fourier]='share = 0.55' [compartments]='contrast = "0.2 contrast"'
  [voronoi]=$'amplitude = "0.1 contrast"\nwall = "0.15 contrast"' [decoys]=$'blobs = 10\ntubes = 6\nplates = 3' [bone]='count = 1'
  [calcification]='count = 10' [inflow]='length = "20 mm"' [slab]=$'thickness = "8 mm"\ndrop = 0.5'
  [projection]=$'tail = 0.5\ntail_length = "8 voxel"\nshadow_length = "6 voxel"' [speckle]='looks = 2'
)
effects=$("$as" effects | sed -n 's/^- \*\*`\([a-z_0-9]*\)`\*\*.*/\1/p')
mkdir -p "$work/effects"
for e in $effects; do
  [ -n "${effect[$e]+set}" ] || { echo "gallery.sh: no gallery values for the effect $e; add them above" >&2; exit 1; }
  printf 'background = 40\nvessel = 300\ndtype = "float32"\n[[effect]]\ntype = "%s"\n%b\n' "$e" "${effect[$e]}" > "$work/effects/$e.toml"
done
"$as" generate examples/vascusynth_like.toml --out "$work/effect_images" --format nifti --quiet \
  --profile "$(for e in $effects; do printf '%s,' "$work/effects/$e.toml"; done | sed 's/,$//')"
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
EOF

/usr/bin/python3 - "$work" "$out" $effects <<'EOF'
import os, sys
import nibabel as nib
import numpy as np
from PIL import Image, ImageDraw
w, out, effects = sys.argv[1], sys.argv[2], sys.argv[3:]

def grey(a, lo=None, hi=None, up=True):
    """Rows are the second axis; `up`: it grows upwards (a view from above), else downwards (depth)."""
    lo = np.percentile(a, 0.5) if lo is None else lo
    hi = np.percentile(a, 99.8) if hi is None else hi
    g = (255 * np.clip((a - lo) / max(hi - lo, 1e-9), 0, 1)).astype(np.uint8)
    return Image.fromarray(g[::-1] if up else g)

def panel(im, text, size=170):
    im = im.resize((size, size), Image.NEAREST if im.size[0] >= size else Image.LANCZOS)
    canvas = Image.new("L", (size, size + 16), 255)
    canvas.paste(im, (0, 16))
    ImageDraw.Draw(canvas).text((3, 2), text, fill=0)
    return canvas

def row(sample, image, name, axis):
    """The truth's slice through most vessel, the image's same slice, and the image's projection,
    along `axis` (z from above; y from the side for effects along the depth axis)."""
    load = lambda f: np.asanyarray(nib.load(os.path.join(w, sample, f)).dataobj).astype(np.float32)
    a, mask = load(image), load("mask.nii.gz")
    a, mask = np.moveaxis(a, axis, 2), np.moveaxis(mask, axis, 2)
    k = int(np.argmax(mask.sum(axis=(0, 1))))
    up = axis == 2
    panels = [panel(grey(mask[:, :, k].T, 0, 1, up), f"truth: slice {k}"), panel(grey(a[:, :, k].T, up=up), f"{name}: slice {k}"),
              panel(grey(a.max(2).T, np.percentile(a, 0.5), np.percentile(a.max(2), 99.8), up), f"{name}: projection")]
    strip = Image.new("L", (sum(p.size[0] for p in panels) + 4 * (len(panels) - 1), panels[0].size[1]), 255)
    x = 0
    for p in panels:
        strip.paste(p, (x, 0))
        x += p.size[0] + 4
    return strip

depth = {"attenuation", "projection", "slab"}
for e in effects:
    row("effect_images", f"image_{e}.nii.gz", e, 1 if e in depth else 2).save(f"{out}/effect_{e}.png", optimize=True)
for p in ["cta", "tof_mra", "two_photon", "octa", "vascusynth", "domain_randomisation"]:
    row("profiles", f"image_{p}.nii.gz", p, 1 if p == "octa" else 2).save(f"{out}/profile_{p}.png", optimize=True)
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
