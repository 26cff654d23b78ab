#!/usr/bin/env bash
# Kills a dataset run with SIGKILL at random moments (KILLS times), resumes it each time, and
# checks that the finished dataset verifies with nothing missing.
#   tests/kill_resume.sh ANGIOSYNTH_EXE SPEC WORKDIR [KILLS]
set -uo pipefail
exe=$1 spec=$2 work=$3 kills=${4:-12}
rm -rf "$work" && mkdir -p "$work"
RANDOM=7
killed=0
for ((n = 0; n < kills; ++n)); do
  "$exe" dataset "$spec" --out "$work" --resume --quiet >/dev/null 2>&1 &
  pid=$!
  sleep "0.$((RANDOM % 9 + 1))$((RANDOM % 10))"
  if kill -9 "$pid" 2>/dev/null; then killed=$((killed + 1)); fi
  wait "$pid" 2>/dev/null
done
echo "killed $killed of $kills runs"
"$exe" dataset "$spec" --out "$work" --resume --quiet >/dev/null || { echo "final resume failed"; exit 1; }
dir=$(ls -d "$work"/Dataset*)
"$exe" dataset verify "$dir" || exit 1
left=$(find "$dir" -name '*.part' -o -name '*.tmp*' | wc -l)
[ "$left" -eq 0 ] || { echo "$left temporary files left"; exit 1; }
[ "$killed" -ge 10 ] || { echo "only $killed runs were killed before finishing; the test needs >= 10"; exit 1; }
echo "kill/resume: ok"
