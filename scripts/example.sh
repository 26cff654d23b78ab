#!/usr/bin/env bash
# Quick start 1: install what is missing, build, grow the shipped VascuSynth-like example.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
build/angiosynth generate examples/vascusynth_like.toml --out out/vascusynth_like --force
echo "wrote out/vascusynth_like/: sample.json, graphs (GXL, DOT, CSV, VTP, SWC, GraphML), image and label volumes, image_vascusynth and image_cta"
