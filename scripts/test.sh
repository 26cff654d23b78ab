#!/usr/bin/env bash
# Quick start 2: install what is missing, build, run every test; then the suite again under
# address and undefined-behaviour sanitizers, and a short fuzzing run of every input parser
# (scripts/sanitize.sh; FUZZ_SECONDS per target, default 20).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
(cd build && ctest --output-on-failure -j "$(nproc)")
bash scripts/sanitize.sh
