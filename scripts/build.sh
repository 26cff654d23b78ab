#!/usr/bin/env bash
# Configures (Release unless BUILD_TYPE says otherwise) and builds into build/: the targets
# named as arguments (e.g. the program alone: angiosynth), else everything (tests, benchmarks).
set -euo pipefail
cd "$(dirname "$0")/.."
# PROGRAM_ONLY=1: the program's packages and targets alone (scripts/example.sh).
if [ -n "${PROGRAM_ONLY:-}" ]; then
  bash scripts/install-deps.sh program
  tests=OFF
else
  bash scripts/install-deps.sh
  tests=ON
fi
# ccache hits across clones (CI builds a fresh clone): paths below the checkout count as relative.
export CCACHE_BASEDIR="$(pwd)" CCACHE_NOHASHDIR=1
# Units compiled with a precompiled header are cached only with these sloppiness flags.
export CCACHE_SLOPPINESS=pch_defines,time_macros,include_file_mtime,include_file_ctime
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S . -B build -DCMAKE_BUILD_TYPE="${BUILD_TYPE:-Release}" -DANGIOSYNTH_WERROR="${WERROR:-OFF}" -DANGIOSYNTH_TESTS="$tests" "${launcher[@]}" >/dev/null
echo "building ${*:-everything} in build/ ..." >&2
cmake --build build -j "$(nproc)" ${1:+--target "$@"}
