#!/usr/bin/env bash
# Times the 200-sample 128^3 dataset (N = 500, cta) on this machine and verifies it.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-/tmp/angiosynth_bench_dataset}
rm -rf "$out"
start=$(date +%s.%N)
/usr/bin/time -f "peak RSS %M KiB" build/angiosynth dataset bench/dataset_200_128.toml --out "$out" --quiet >/dev/null
end=$(date +%s.%N)
echo "200 samples of 128^3: $(echo "$end - $start" | bc) s"
build/angiosynth dataset verify "$out"/Dataset990_VesselBench
du -sh "$out"/Dataset990_VesselBench
