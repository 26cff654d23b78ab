#!/bin/bash
# Rewrites the generated blocks of docs/ from the program, so that the pages cannot drift from
# the code (the test suite compares them: Docs.*). A block is the text between
#   <!-- generated: ARGS -->   and   <!-- end generated -->
# and holds the output of `angiosynth ARGS`: as it is for the Markdown references (methods,
# effects), in a text block otherwise (params, --help).
# Usage: bash scripts/docs.sh [BUILD_DIR]   (default build; the program must be built)
set -euo pipefail
cd "$(dirname "$0")/.."
build="${1:-build}"
[ -x "$build/angiosynth" ] || { echo "docs.sh: $build/angiosynth is not built; run scripts/build.sh first" >&2; exit 2; }
PATH="$(cd "$build" && pwd):$PATH" /usr/bin/python3 - docs/*.md docs/*/*.md <<'EOF'
import re, subprocess, sys

MARK = re.compile(r"(<!-- generated: (.+?) -->\n)(.*?)(<!-- end generated -->)", re.S)
MARKDOWN = {"methods", "effects"}

def output(args):
    # The program as `angiosynth` on PATH: its help names itself so.
    text = subprocess.run(["angiosynth"] + args.split(), check=True, capture_output=True, text=True).stdout
    return text if args in MARKDOWN else "```text\n" + text.rstrip("\n") + "\n```\n"

for path in sys.argv[1:]:
    page = open(path, encoding="utf-8").read()
    new = MARK.sub(lambda m: m.group(1) + output(m.group(2)) + m.group(4), page)
    if new != page:
        open(path, "w", encoding="utf-8").write(new)
        print("updated", path)
EOF
