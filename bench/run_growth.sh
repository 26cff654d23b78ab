#!/usr/bin/env bash
# Prints growth time and peak memory at 1k, 10k, 100k terminals, one process per size.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh >/dev/null
printf "%-10s %12s %16s %14s %10s\n" terminals "time (s)" "us/terminal" "peak RSS MiB" "pairs"
for n in 1000 10000 100000; do
  build/bench_growth --benchmark_filter="BM_GrowVascuSynth/$n/" --benchmark_format=json 2>/dev/null |
    python3 -c '
import json, sys
b = json.load(sys.stdin)["benchmarks"][0]
print("%-10d %12.3f %16.2f %14.1f %10d" % (b["terminals"], b["real_time"] / 1e3, b["us_per_terminal"] * 1e6,
      b["peak_rss_MiB"], b["intersecting_pairs"]))'
done
