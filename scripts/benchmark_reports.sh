#!/usr/bin/env bash
# Runs every shipped benchmark (examples/benchmarks/*.toml with a [benchmark] table) from scratch,
# writes each one's results table and wall time into docs/benchmark-ladders.md (between
# <!-- benchmark-results: NAME --> and <!-- end benchmark-results -->) and a screenshot of the
# VascuSynth-style report into docs/gallery/benchmark_report.png (headless Chromium).
# Usage: bash scripts/benchmark_reports.sh [BUILD_DIR] [OUT_DIR]   (OUT_DIR must not exist)
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
out="${2:-$(mktemp -d)/benchmarks}"
[ -x "$build/angiosynth" ] || { echo "benchmark_reports.sh: $build/angiosynth is not built; run scripts/build.sh first" >&2; exit 2; }
[ -e "$out" ] && { echo "benchmark_reports.sh: $out exists; give a new directory" >&2; exit 2; }
command -v chromium >/dev/null || { echo "benchmark_reports.sh: needs Debian's chromium (scripts/install-deps.sh)" >&2; exit 2; }
mkdir -p "$out"
commit="$(git rev-parse --short HEAD)"
cores="$(nproc)"
for spec in examples/benchmarks/*.toml; do
  grep -q '^\[benchmark\]' "$spec" || continue
  name="$(basename "$spec" .toml)"
  start=$SECONDS
  "$build/angiosynth" benchmark "$spec" --out "$out/$name" --quiet
  echo "$name $((SECONDS - start))" >> "$out/wall_seconds.txt"
  echo "benchmark_reports.sh: $name done ($out/$name/report.html)" >&2
done
chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --window-size=1100,1500 \
  --screenshot="$PWD/docs/gallery/benchmark_report.png" "file://$out/vascusynth_noise_bifurcations/report.html" >/dev/null 2>&1
/usr/bin/python3 - "$out" "$commit" "$cores" <<'PY'
import csv, re, sys
out, commit, cores = sys.argv[1:]
wall = dict(l.split() for l in open(f"{out}/wall_seconds.txt"))
def table(name):
    rows = list(csv.DictReader(open(f"{out}/{name}/results.csv")))
    methods = list(dict.fromkeys(r["method"] for r in rows))
    text = []
    for ladder in dict.fromkeys(r["ladder"] for r in rows):
        rs = [r for r in rows if r["ladder"] == ladder]
        text.append(f"\nLadder `{ladder}`: mean Dice (clDice) over {rs[0]['cases']} cases per rung\n")
        text.append("| rung | " + " | ".join(methods) + " |")
        text.append("|---|" + "---|" * len(methods))
        for rung in dict.fromkeys(r["rung"] for r in rs):
            cells = {r["method"]: r for r in rs if r["rung"] == rung}
            label = next(iter(cells.values()))["label"]
            text.append(f"| {label} | " + " | ".join(f"{float(cells[m]['dice']):.3f} ({float(cells[m]['cldice']):.3f})" for m in methods) + " |")
    text.append(f"\n`angiosynth benchmark examples/benchmarks/{name}.toml --out DIR`: {float(wall[name]):.0f} s on {cores} cores (commit {commit}, `bash scripts/benchmark_reports.sh`).\n")
    return "\n".join(text)
path = "docs/benchmark-ladders.md"
page = open(path, encoding="utf-8").read()
mark = re.compile(r"(<!-- benchmark-results: (.+?) -->\n)(.*?)(<!-- end benchmark-results -->)", re.S)
page = mark.sub(lambda m: m.group(1) + table(m.group(2)) + m.group(4), page)
open(path, "w", encoding="utf-8").write(page)
print("updated", path)
PY
echo "benchmark_reports.sh: reports in $out" >&2
