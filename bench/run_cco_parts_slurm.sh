#!/usr/bin/env bash
# A CCO tree grown in parts by a real Slurm array (examples/cluster/slurm_cco_parts.sh) and joined
# by a dependent job, then by one process: the wall time of each, the slowest task, the join's
# peak memory, the joined tree's checks (sample.json), and whether the two samples are
# byte-identical (sample.json's command line and times apart). Needs sbatch; on one machine,
# scripts/local_slurm.sh makes a one-node Slurm.
#   bash bench/run_cco_parts_slurm.sh [BUILD_DIR] [TERMINALS] [PARTS] [CPUS_PER_TASK]   (default build 1000000 8 1)
set -euo pipefail
build=$(cd "${1:-build}" && pwd); n=${2:-1000000}; parts=${3:-8}; cpus=${4:-1}
command -v sbatch >/dev/null || { echo "run_cco_parts_slurm.sh: no sbatch (scripts/local_slurm.sh sets up a one-node Slurm)" >&2; exit 1; }
work=$(mktemp -d -t angiosynth_cco_parts_XXXX)
sed -e "s/^terminals = .*/terminals = $n/" -e "s/^parts = [0-9]*/parts = $parts/" examples/cco_organ_parts_3d.toml >"$work/organ.toml"
t0=$(date +%s.%N)
job=$(sbatch --parsable --array=0-$((parts - 1)) --cpus-per-task="$cpus" --mem=3G -o "$work/task_%a.log" \
  --export=ALL,PATH="$build:$PATH",PARAMS="$work/organ.toml",OUT="$work/slurm" examples/cluster/slurm_cco_parts.sh)
sbatch --wait --parsable --dependency=afterok:"$job" --kill-on-invalid-dep=yes --cpus-per-task="$cpus" --mem=6G -o "$work/join.log" \
  --wrap "/usr/bin/time -f 'join: peak RSS %M kB, wall %e s' $build/angiosynth generate $work/organ.toml --out $work/slurm --join --threads $cpus --quiet" >/dev/null ||
  { echo "run_cco_parts_slurm.sh: a task or the join failed; logs in $work" >&2; tail -n 3 "$work"/*.log >&2; exit 1; }
t1=$(date +%s.%N)
/usr/bin/time -f "one process: peak RSS %M kB, wall %e s" "$build/angiosynth" generate "$work/organ.toml" --out "$work/one" --quiet
cat "$work/join.log"
/usr/bin/python3 - "$work" <<'PY'
import json, os, sys
w = sys.argv[1]
a, b = (json.load(open(os.path.join(w, d, "sample.json"))) for d in ("slurm", "one"))
s = a["statistics"]
import glob, re
grown = [float(m.group(1)) for f in sorted(glob.glob(os.path.join(w, "task_*.log")))
         for m in [re.search(r"terminals, ([0-9.e+-]+) s growth", open(f).read())] if m]
print("part tasks: growth %s s (slowest %.1f s)" % (" ".join("%.1f" % g for g in grown), max(grown) if grown else 0))
d = s["decomposition"]
print("joined tree: %d terminals, %d intersecting pairs, %d short, %d outside; part radius scale %.3f-%.3f, trunk radius share %.3f, "
      "part pressure share %.3f, %d regrown parts; volume %.1f mm^3" % (
          s["terminals"], s["intersecting_pairs"], s["short_segments"], s["outside_segments"], d["part_radius_scale"][0],
          d["part_radius_scale"][1], d["trunk_radius_share"], d["part_pressure_share"], d["regrown_parts"], s["total_volume"]["value"]))
for j in (a, b):
    j.pop("command_line"); j.pop("timing_seconds")
same = a == b and all(open(os.path.join(w, "slurm", f), "rb").read() == open(os.path.join(w, "one", f), "rb").read()
                      for f in os.listdir(os.path.join(w, "one")) if f != "sample.json")
print("slurm sample against one process's:", "byte-identical" if same else "DIFFERENT")
sys.exit(0 if same else 1)
PY
printf "slurm: %d array tasks (%d CPU each) and the join: %s s wall\n" "$parts" "$cpus" "$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }')"
echo "samples in $work (remove when done)"
