#!/usr/bin/env bash
# Quick start 1: install what is missing, build, grow the shipped VascuSynth-like example and the
# faithful-CCO sphere.
set -euo pipefail
cd "$(dirname "$0")/.."
PROGRAM_ONLY=1 bash scripts/build.sh angiosynth angiosynth_python_sources  # the program (with its OpenVDB module) and the Python module; scripts/test.sh installs and builds the rest
build/angiosynth generate examples/vascusynth_like.toml --out out/vascusynth_like --force
echo "wrote out/vascusynth_like/: sample.json, graphs (GXL, DOT, CSV, VTP, SWC, GraphML), image and label volumes, image_vascusynth and image_cta"
build/angiosynth generate examples/cco_sphere_3d.toml --out out/cco_sphere_3d --force
echo "wrote out/cco_sphere_3d/: a 4000-terminal CCO tree (Kerautret et al. (OpenCCO) §5) with its graphs and volumes"
