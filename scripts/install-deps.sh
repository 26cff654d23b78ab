#!/usr/bin/env bash
# Installs the Debian packages angiosynth builds and tests with, only those missing.
set -euo pipefail
# `install-deps.sh program`: what the program needs to build (scripts/example.sh); with no
# argument also what the tests, benchmarks and sanitizer build need (scripts/test.sh).
pkgs=(build-essential cmake pkg-config ccache
      libtbb-dev libtomlplusplus-dev libcli11-dev nlohmann-json3-dev libtinyxml2-dev
      zlib1g-dev libzip-dev libnifti2-dev libtiff-dev libpng-dev libjpeg-dev
      libopenvdb-dev libboost-iostreams-dev libssl-dev libceres-dev libcgal-dev libjemalloc-dev
      libfftw3-dev  # k-space artefacts
      libblosc-dev  # OME-Zarr chunks
      python3-dev pybind11-dev python3-numpy)  # the Python module
if [ "${1:-all}" != program ]; then
  pkgs+=(libgtest-dev libbenchmark-dev
         libopenimageio-dev python3-nibabel python3-networkx python3-scipy python3-skimage python3-vtk9 python3-zarr tetgen  # independent readers and references
         clang libclang-rt-14-dev  # the sanitizer build and libFuzzer (scripts/sanitize.sh)
         clang-format-14  # the style check (scripts/check_format.sh)
         python3-pytest python3-torch  # the Python module's tests and its PyTorch dataset
         chromium fonts-liberation)  # renders the benchmark report headless (its test)
fi
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
echo "installing ${#missing[@]} Debian packages (and what they need): ${missing[*]}" >&2
sudo=""; [ "$(id -u)" -ne 0 ] && sudo="sudo"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
# apt's own progress (one line per package), so a long first install is visibly moving.
$sudo apt-get install -y --no-install-recommends -o Dpkg::Use-Pty=0 "${missing[@]}" | grep -E '^(Get|Setting up)' >&2 || true
for p in "${missing[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || { echo "could not install $p" >&2; exit 1; }
done
