#!/usr/bin/env bash
# CCO growth in the Kerautret et al. (OpenCCO) §5 sphere (100 cm³, 500 mL/min) for N = 1k … 50k terminals, and the
# 2D disc: seconds, µs per terminal, and µs per terminal / log2 N (flat = O(N log N) overall).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh >/dev/null
build/bench_cco 1000 2000 4000 8000 16000 32000 50000
build/bench_cco 4000 --disc
build/bench_cco 4000 20000 --murray-bands
# Organ scale ([tree] organ_scale): 10^4 … 10^6 terminals (the last takes about 5 minutes).
build/bench_cco 10000 100000 1000000 --organ-scale
