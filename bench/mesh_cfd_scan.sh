#!/bin/bash
# Every shipped example grown (no image) and meshed for CFD, with capped ends and a flow
# extension of 5 radii: per example its trees, ends, the ends whose extension was shortened or
# that were left closed, and whether each tree's surface has the Euler characteristic its graph
# implies. Writes OUT/scan.md (a Markdown table) and each example's sample and mesh in OUT.
#
#     [MESH_SECONDS=900] bench/mesh_cfd_scan.sh [BUILD_DIR] [OUT]     (defaults: build, out/mesh_cfd_scan)
#
# Left out: the dataset specs (not single samples) and large_100k.toml (100,000 terminals: a
# memory-bound mesh of its own, see bench/mesh_cco_50000.toml).
set -euo pipefail
SOURCE=$(cd "$(dirname "$0")/.." && pwd)
BUILD=$(cd "${1:-$SOURCE/build}" && pwd)
OUT=${2:-out/mesh_cfd_scan}
mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
table="$OUT/scan.md"
printf '| example | trees | ends | extension shortened | left closed | Euler characteristic by tree (expected) | as expected | mesh s |\n|---|---|---|---|---|---|---|---|\n' > "$table"
for params in "$SOURCE"/examples/*.toml; do
  name=$(basename "$params" .toml)
  case "$name" in dataset_* | large_100k) continue ;; esac
  rm -rf "$OUT/$name" "$OUT/${name}_mesh"
  (cd "$SOURCE/examples" && "$BUILD/angiosynth" generate "$params" --out "$OUT/$name" --no-image --quiet)
  start=$(date +%s.%N)
  status=0
  timeout "${MESH_SECONDS:-900}" "$BUILD/angiosynth" mesh "$OUT/$name" --out "$OUT/${name}_mesh" --ends capped --flow-extension 5 --quiet \
    2> "$OUT/${name}_mesh.warnings" || status=$?
  if [ "$status" = 124 ]; then
    printf '| %s | not finished in %s s |||||||\n' "$name" "${MESH_SECONDS:-900}" >> "$table"
    continue
  elif [ "$status" != 0 ]; then
    printf '| %s | refused: %s |||||||\n' "$name" "$(tail -1 "$OUT/${name}_mesh.warnings")" >> "$table"
    continue
  fi
  end=$(date +%s.%N)
  /usr/bin/python3 - "$OUT/${name}_mesh/mesh.json" "$name" "$start" "$end" >> "$table" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))["statistics"]
chi, want, parts = s["tree_euler_characteristic"], s["tree_euler_expected"], s["tree_components"]
ok = chi == want and all(c == 1 for c in parts)
# Every tree as expected in a word; else each tree that is not, as "tree: found (expected)".
found = ("every tree " + str(want[0]) if len(set(want)) == 1 else "as expected") if ok else \
    ", ".join(f"{t}: {c} ({w})" for t, (c, w, p) in enumerate(zip(chi, want, parts)) if c != w or p != 1)
print(f"| {sys.argv[2]} | {s['trees']} | {s['ends']} | {s['ends_extension_shortened']} | {s['ends_left_closed']} | "
      f"{found} | {'yes' if ok else '**no**'} | {float(sys.argv[4]) - float(sys.argv[3]):.1f} |")
PY
done
cat "$table"
