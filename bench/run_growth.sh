#!/usr/bin/env bash
# Prints growth time and peak memory at 1k, 10k, 100k terminals, one process per size.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh >/dev/null
printf "%-14s %-10s %10s %13s %14s %7s\n" map terminals "time (s)" "us/terminal" "peak RSS MiB" pairs
for case in 1000/uniform200:0 10000/uniform200:0 1000/uniform200:1 10000/uniform200:1 100000/uniform200:1; do
  build/bench_growth --benchmark_filter="BM_GrowVascuSynth/terminals:${case}/" --benchmark_format=json 2>/dev/null |
    python3 -c '
import json, sys
b = json.load(sys.stdin)["benchmarks"][0]
m = "uniform 200^3" if b["map"] else "rods 100^3"
print("%-14s %-10d %10.3f %13.1f %14.1f %7d" % (m, b["terminals"], b["real_time"] / 1e3, b["us_per_terminal"] * 1e6,
      b["peak_rss_MiB"], b["intersecting_pairs"]))'
done
