#!/usr/bin/env bash
# Checks that every C++ source keeps the style of .clang-format (clang-format 14, Debian 12's),
# as the test Lint.SourcesAreFormatted does in CI; `--fix` formats them instead.
set -euo pipefail
cd "$(dirname "$0")/.."
mapfile -t files < <(find src apps python tests bench fuzz \( -name '*.cpp' -o -name '*.hpp' \) | sort)
if [ "${1:-}" = --fix ]; then
  clang-format-14 -i "${files[@]}"
else
  clang-format-14 --dry-run --Werror "${files[@]}"
fi
