#!/usr/bin/env bash
# The test suite under address + undefined-behaviour sanitizers (float-cast overflow included), built
# with clang into build-san/, then a short libFuzzer run of every input parser.
#   FUZZ_SECONDS   seconds per fuzz target (default 20; 0 skips fuzzing)
# Sanitizer reports of any process, the angiosynth runs the tests start included, go to
# build-san/sanitizer-logs/; one report there fails this script.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
root=$(pwd)
export CCACHE_BASEDIR="$root" CCACHE_NOHASHDIR=1
# Units compiled with a precompiled header are cached only with these sloppiness flags.
export CCACHE_SLOPPINESS=pch_defines,time_macros,include_file_mtime,include_file_ctime
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S . -B build-san -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
      -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only" \
      -DANGIOSYNTH_SANITIZE=ON -DANGIOSYNTH_FUZZ=ON -DANGIOSYNTH_BENCH=OFF -DANGIOSYNTH_PYTHON=OFF "${launcher[@]}" >/dev/null
cmake --build build-san -j "$(nproc)"
logs="$root/build-san/sanitizer-logs"
rm -rf "$logs" && mkdir -p "$logs"
# Leak checking is off: TBB's and OpenVDB's process-lifetime singletons read as leaks. The shadow
# memory follows the kernel's huge-page policy rather than ASan's small pages only: tests that
# sweep large grids spent much of their time on the shadow's pages (docs/benchmarks.md).
export ASAN_OPTIONS="log_path=$logs/asan:detect_leaks=0:abort_on_error=0:exitcode=86:no_huge_pages_for_shadow=0"
export UBSAN_OPTIONS="log_path=$logs/ubsan:print_stacktrace=1:halt_on_error=1:exitcode=86:suppressions=$root/sanitizer/ubsan.supp"
# Four long checks of the mesher's results are left out here (TetGen, VTK and volume comparisons
# on large surfaces: 250 s of the release suite, several times that under the sanitizers): the
# same meshing code runs under the sanitizers in the other mesh tests and in the mesh fuzz targets.
# So is the shipped noise ladder (37 s of scoring 144 masks): the other Benchmark tests run the
# same code on a smaller ladder. And the README's commands (the longest test under the
# sanitizers, 137 s): the commands they run are each run under the sanitizers by the Cli,
# Dataset, Score and Benchmark tests. And the example outputs' hashes: their record is of the
# release compiler, so under clang the test grew every example (313 s, the longest test here) only
# to skip the comparison; the growth methods, writers, profiles and meshes the examples use run
# under the sanitizers in the Shipped, Cli, Dataset, Degrade and Mesh tests.
release_only='^(Mesh\.(TetgenFindsNoSelfIntersectionInAnyFormat|SliverRepairKeepsTopologyVolumeAndSurface|WrittenFilesReadBackClosedByVtkWithTheUnionsVolume|RemeshingMakesTheNetsTrianglesAcuteAndKeepsTheSurface)|Benchmark\.ShippedNoiseLadderDiceFallsForEveryBaseline|Docs\.ReadmeCommandsRun|ExampleOutputs\.EveryFileTheShippedExamplesWriteIsByteIdenticalToTheRecord)$'
(cd build-san && ctest --output-on-failure -j "$(nproc)" --timeout 900 -E "$release_only")
if compgen -G "$logs/*" >/dev/null; then
  echo "sanitizer reports:"; head -n 60 "$logs"/*; exit 1
fi
echo "sanitizers: no report from the test suite or the processes it ran"
bash scripts/fuzz.sh "${FUZZ_SECONDS:-20}"
