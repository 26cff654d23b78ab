#!/usr/bin/env python3
"""Fails on random draws whose order C++ leaves unspecified.

Two draws from one stream as arguments of one call (`Vec3(rng.uniform(), rng.uniform(), ...)`)
or as operands of one operator (`rng.uniform() - rng.uniform()`) are unsequenced: GCC evaluated
them right to left, Clang left to right, and the two compilers grew different trees from one
seed. Draws in separate declarators (`a = rng.uniform(), b = rng.uniform()`), in the branches of
`?:`, or in a braced list are sequenced and pass.

  check_draw_order.py SOURCE_DIR     (reads src/, tests/, bench/; exit 1 with file:line per find)
"""
import pathlib
import re
import sys

DRAW = re.compile(r"\b\w+(?:\.|->)(?:uniform|uniformOpen|normal|nextU64)\(")
OPEN, CLOSE = "([", ")]"


def code_only(text):
    """Comments and string literals blanked, offsets kept."""
    out, i, n = list(text), 0, len(text)
    while i < n:
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
        elif text[i] == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            j += 1
        else:
            i += 1
            continue
        for k in range(i, min(j, n)):
            if out[k] != "\n":
                out[k] = " "
        i = j
    return "".join(out)


def sequenced(stmt, a, b):
    """Whether draws starting at a < b in stmt are sequenced. Between them, at the level of the
    innermost group that holds both: a `?` or `:` (branches) sequences them, and so does a comma
    at the statement's top level (declarators, the comma operator); a comma inside a group is
    one between a call's arguments."""
    base = 0
    for c in stmt[:a]:
        base += (c in OPEN) - (c in CLOSE)
    depth, low = 0, 0
    for c in stmt[a:b]:
        depth += (c in OPEN) - (c in CLOSE)
        low = min(low, depth)
    depth = 0
    for k in range(a, b):
        c = stmt[k]
        depth += (c in OPEN) - (c in CLOSE)
        if depth != low or c in OPEN or c in CLOSE:
            continue
        if c == "?" or (c == ":" and stmt[k - 1] != ":" and stmt[k + 1] != ":"):
            return True
        if c == "," and base + low == 0:
            return True
    return False


def finds(path):
    text = code_only(path.read_text(errors="replace"))
    for m in re.finditer(r"[^;{}]+", text):
        stmt = m.group(0)
        draws = [d.start() for d in DRAW.finditer(stmt)]
        for x, y in zip(draws, draws[1:]):
            if not sequenced(stmt, x, y):
                yield text.count("\n", 0, m.start() + x) + 1, " ".join(stmt.split())[:120]
                break


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
    bad = 0
    for sub in ("src", "tests", "bench"):
        for p in sorted((root / sub).rglob("*.[ch]pp")):
            for line, stmt in finds(p):
                print(f"{p.relative_to(root)}:{line}: random draws in unspecified order: {stmt}\n"
                      "  allowed: one draw per declarator or statement (uniformPoint for points)")
                bad += 1
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
