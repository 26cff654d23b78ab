#!/usr/bin/env bash
# Inputs whose work grows faster than their size: straight chains and stars in an [initial]
# network, curve pieces far below the vessels, a kilometre-long vessel meshed under a small
# memory limit. Each is grown or refused up front; the table gives exit code, wall time, peak
# memory and the first line of the refusal.
#   bash bench/hostile_inputs.sh [EXE] [WORK_DIR]        (TIMEOUT=SECONDS per case, default 120)
set -uo pipefail
exe=$(realpath "${1:-$(dirname "$0")/../build/angiosynth}")
cd "$(dirname "$0")/.."
root=$(pwd)
work=${2:-$(mktemp -d)}
limit=${TIMEOUT:-120}
mkdir -p "$work" && cd "$work"

chain() {  # N pieces, 10 mm in all, radius 0.2 mm, along y from (0, -20)
  awk -v n="$1" 'BEGIN { print "1 1 0 -20 0 0.2 -1"; for (k = 0; k < n; ++k) printf "%d 3 0 %.6f 0 0.2 %d\n", k + 2, -20 + (k + 1) * 10 / n, k + 1 }'
}
star() {  # a trunk of 1 mm and N children of 0.05 mm radius on a circle of 3 mm
  awk -v n="$1" 'BEGIN { print "1 1 0 0 0 0.2 -1"; print "2 3 0 1 0 0.2 1";
                         for (k = 0; k < n; ++k) printf "%d 3 %.6f %.6f 0 0.05 2\n", k + 3, cos(k * 0.00314) * 3, 1 + sin(k * 0.00314) * 3 }'
}
dcco() {  # DCCO continuing $1 in a disc of 20 mm, 20 terminals
  printf 'seed = 1\n[domain]\nshape = "disc"\nradius = "20 mm"\nvoxel_size = "0.1 mm"\n[tree]\nmethod = "dcco"\nroot_radius = "0.2 mm"\n'
  printf '[initial]\nfile = "%s"\nbranching = "versatile"\nrole = "distribution"\n[physics]\nperfusion_flow = "0.33 mL/min"\n' "$1"
  printf '[[stage]]\nterminals = 20\n[image]\nformats = []\n'
}
colonisation() {  # space colonisation continuing $1 in a disc of 10 mm
  printf 'seed = 1\n[domain]\nshape = "disc"\nradius = "10 mm"\nvoxel_size = "0.2 mm"\n[tree]\nmethod = "colonisation"\nveins = false\n'
  printf '[initial]\nfile = "%s"\n[[stage]]\nsteps = 8\ndrains_per_step = 100\n[image]\nformats = []\n' "$1"
}

chain 50 > chain50.swc && dcco chain50.swc > chain50.toml
chain 1000 > chain1000.swc && dcco chain1000.swc > chain1000.toml
star 2000 > star2000.swc && dcco star2000.swc > star2000_dcco.toml && colonisation star2000.swc > star2000_colonisation.toml
star 100000 > star100k.swc
printf '1 1 0 0 0 0.1 -1\n2 3 1e6 0 0 0.1 1\n' > km.swc
for p in 1e-4 1e-3; do
  sed -e 's/terminals = 4000/terminals = 50/' -e "s/^wall_clearance/piece_length = \"$p mm\"\nwall_clearance/" \
    "$root/examples/cco_sphere_curved_3d.toml" > "curves_$p.toml"
done

printf '| case | command | exit | wall s | peak MB | message |\n|---|---|---|---|---|---|\n'
one() {
  local name=$1; shift
  rm -rf out_"$name"
  local start end code
  start=$(date +%s.%N)
  timeout "$limit" /usr/bin/time -f "%M" -o "time_$name" "$exe" "$@" --out "out_$name" --quiet >/dev/null 2>"err_$name"
  code=$?
  end=$(date +%s.%N)
  local rss; rss=$(tail -n 1 "time_$name" 2>/dev/null | grep -E '^[0-9]+$' || echo "")
  local msg; msg=$(grep -v '^Command' "err_$name" | head -n 1 | cut -c 1-110)
  [ "$code" = 124 ] && msg="stopped after $limit s"
  printf '| %s | `%s` | %s | %.2f | %s | %s |\n' "$name" "$*" "$code" "$(echo "$end - $start" | bc)" \
    "${rss:+$((rss / 1024))}" "$msg"
}
one chain50 generate chain50.toml --no-image
one chain1000 generate chain1000.toml --no-image
one star2000_dcco generate star2000_dcco.toml --no-image
one star2000_colonisation generate star2000_colonisation.toml --no-image
one star2000_mesh mesh star2000.swc
one star100k_mesh mesh star100k.swc
one curves_1e-4 generate curves_1e-4.toml --no-image
one curves_1e-3 generate curves_1e-3.toml --no-image
one km_vessel_mesh mesh km.swc --memory-limit 0.1
