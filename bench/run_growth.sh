#!/usr/bin/env bash
# Prints growth time and peak memory of VascuSynth mode at 1k, 10k, 100k terminals, one process per
# size, with the no-stub rule (the default) and without it (min_length_ratio = 0, relax_sweeps = 0).
#   bash bench/run_growth.sh [BENCH_BINARY]     (default build/bench_growth, built first)
set -euo pipefail
cd "$(dirname "$0")/.."
exe=${1:-}
if [ -z "$exe" ]; then
  bash scripts/build.sh bench_growth >/dev/null
  exe=build/bench_growth
fi
printf "%-14s %-10s %-7s %10s %13s %14s %9s %7s\n" map terminals stubs "time (s)" "us/terminal" "peak RSS MiB" repaired pairs
for case in 1000/uniform200:0 10000/uniform200:0 1000/uniform200:1 10000/uniform200:1 100000/uniform200:1; do
  for stubs in 0 1; do
    "$exe" --benchmark_filter="BM_GrowVascuSynth/terminals:${case}/stubs:${stubs}/" --benchmark_format=json 2>/dev/null |
      /usr/bin/python3 -c '
import json, sys
b = json.load(sys.stdin)["benchmarks"][0]
m = "uniform 200^3" if b["map"] else "rods 100^3"
print("%-14s %-10d %-7s %10.3f %13.1f %14.1f %9d %7d" % (m, b["terminals"], "allowed" if b["stubs_allowed"] else "refused",
      b["real_time"] / 1e3, b["us_per_terminal"] * 1e6, b["peak_rss_MiB"], b["repaired"], b["intersecting_pairs"]))'
  done
done
