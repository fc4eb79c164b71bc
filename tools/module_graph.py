#!/usr/bin/env python3
"""The import graph among spatter's top-level modules, and its cycles.

A top-level module is `src/X.rs` or `src/X/` (every file under it). An edge
X -> Y is a reference to `crate::Y` (a `use crate::Y...`, a grouped
`use crate::{Y, ...}`, or a path `crate::Y::...` in code) from a file of X, or a
`super::Y` from X's own root file (`src/X.rs`, `src/X/mod.rs`). Comments and
string literals are skipped. Code under `#[cfg(test)]` is left out: a unit test
may load a scene through `run::load` without the module depending on the run
(`--tests` counts it too).

Prints every module with the modules it uses, then every cycle: a strongly
connected component of more than one module. A cycle listed in `EXPLAINED`
(below, each with its reason; ARCHITECTURE.md "Module boundaries" says the same)
is reported as explained; any other makes the tool exit 1, and so does (with
`--tests`) an explained cycle that no longer exists. CI runs it with `--tests`.

Usage: python3 tools/module_graph.py [--tests] [--dot]
"""

import os
import re
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src")

# Each remaining cycle, as the sorted tuple of its modules, with why it stays
# (ARCHITECTURE.md, "Module boundaries", says the same).
EXPLAINED = {
    ("fields", "output", "solidification", "state"): (
        "the field registry lists State's arrays (state.rs iterates it for the "
        "compared fields) and names each field's frame channels, which output's "
        "frame builder iterates: one table over three files, so a field is "
        "declared once; the solidification record's channels carry R, which "
        "solidification.rs derives from the records around each particle (it "
        "reads State and nothing above it)"
    ),
    ("kernel", "params"): (
        "tests only: params.rs evaluates the kernel on the block it builds (W(0) "
        "for the wall-weight floor, the surface-delta integral), so the constants "
        "it bakes in are those of the kernel the passes run; kernel.rs's unit tests "
        "build a parameter block to evaluate the kernels as the passes do"
    ),
}


def strip_code(text):
    """The text with comments and string/char literals blanked (newlines kept)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            depth, i = 1, i + 2
            while i < n and depth:
                if text.startswith("/*", i):
                    depth, i = depth + 1, i + 2
                elif text.startswith("*/", i):
                    depth, i = depth - 1, i + 2
                else:
                    out.append("\n" if text[i] == "\n" else "")
                    i += 1
        elif re.match(r'(b?r#*)"', text[i:i + 8]) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'b?r(#*)"', text[i:])
            if m:
                end = '"' + m.group(1)
                j = text.find(end, i + m.end())
                j = n if j < 0 else j + len(end)
                out.append('""' + "\n" * text.count("\n", i, j))
                i = j
            else:
                out.append(c)
                i += 1
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append('""' + "\n" * text.count("\n", i, j))
            i = j + 1
        elif c == "'":
            m = re.match(r"'(\\[^']{1,10}|[^\\'])'", text[i:])
            if m:
                out.append("' '")
                i += m.end()
            else:  # a lifetime
                out.append(c)
                i += 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def drop_cfg_test(code):
    """The code without the items that follow `#[cfg(test)]`."""
    while True:
        m = re.search(r"#\[cfg\(test\)\]", code)
        if not m:
            return code
        j = m.end()
        # The item ends at its matching closing brace, or at a `;` before any brace.
        brace = code.find("{", j)
        semi = code.find(";", j)
        if semi >= 0 and (brace < 0 or semi < brace):
            end = semi + 1
        else:
            depth, k = 0, brace
            while k < len(code):
                if code[k] == "{":
                    depth += 1
                elif code[k] == "}":
                    depth -= 1
                    if depth == 0:
                        break
                k += 1
            end = k + 1
        code = code[: m.start()] + "\n" * code.count("\n", m.start(), end) + code[end:]


def grouped_names(code, start):
    """Top-level names in the `{...}` group that opens at `start`."""
    depth, k, names, cur = 0, start, [], ""
    while k < len(code):
        ch = code[k]
        if ch == "{":
            depth += 1
            if depth > 1:
                cur += ch
        elif ch == "}":
            depth -= 1
            if depth == 0:
                break
            cur += ch
        elif ch == "," and depth == 1:
            names.append(cur)
            cur = ""
        else:
            cur += ch
        k += 1
    names.append(cur)
    out = []
    for name in names:
        m = re.match(r"\s*([a-z_][a-z0-9_]*)", name)
        if m:
            out.append(m.group(1))
    return out


def modules():
    """{module: [files]} for every top-level module of the library."""
    mods = {}
    for entry in sorted(os.listdir(ROOT)):
        path = os.path.join(ROOT, entry)
        if entry.endswith(".rs") and entry not in ("lib.rs", "main.rs"):
            mods.setdefault(entry[:-3], []).append(path)
        elif os.path.isdir(path):
            for dirpath, _, files in os.walk(path):
                mods.setdefault(entry, []).extend(
                    os.path.join(dirpath, f) for f in sorted(files) if f.endswith(".rs"))
    return mods


def graph(with_tests):
    mods = modules()
    edges = {m: set() for m in mods}
    for mod, files in mods.items():
        for f in files:
            with open(f, encoding="utf-8") as fh:
                code = strip_code(fh.read())
            if not with_tests:
                code = drop_cfg_test(code)
            root_file = f == os.path.join(ROOT, mod + ".rs") or f == os.path.join(ROOT, mod, "mod.rs")
            refs = re.findall(r"\bcrate::([a-z_][a-z0-9_]*)", code)
            for g in re.finditer(r"\bcrate::\{", code):
                refs += grouped_names(code, g.end() - 1)
            if root_file:
                refs += re.findall(r"(?<![:\w])super::([a-z_][a-z0-9_]*)", code)
            for r in refs:
                if r in mods and r != mod:
                    edges[mod].add(r)
    return edges


def cycles(edges):
    """Strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, out = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(edges[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(tuple(sorted(comp)))

    sys.setrecursionlimit(10000)
    for v in sorted(edges):
        if v not in index:
            visit(v)
    return sorted(out)


def main():
    with_tests = "--tests" in sys.argv[1:]
    edges = graph(with_tests)
    if "--dot" in sys.argv[1:]:
        print("digraph spatter {")
        for m in sorted(edges):
            for d in sorted(edges[m]):
                print(f"  {m} -> {d};")
        print("}")
        return 0
    width = max(len(m) for m in edges)
    print("module graph (X -> the modules X uses)" + (", tests included" if with_tests else ""))
    for m in sorted(edges):
        print(f"  {m:<{width}} -> {', '.join(sorted(edges[m])) or '-'}")
    found = cycles(edges)
    unexplained = 0
    print("cycles:" if found else "cycles: none")
    for c in found:
        inner = {m: sorted(d for d in edges[m] if d in c) for m in c}
        links = "; ".join(f"{m} -> {', '.join(inner[m])}" for m in c)
        reason = EXPLAINED.get(c)
        if reason is None:
            unexplained += 1
            print(f"  UNEXPLAINED {' <-> '.join(c)} ({links})")
        else:
            print(f"  explained {' <-> '.join(c)} ({links}): {reason}")
    if with_tests:
        # The graph with tests holds every edge of the one without, so an
        # explained cycle missing here is gone for good.
        stale = [c for c in EXPLAINED if c not in found]
        for c in stale:
            print(f"  STALE explained cycle {' <-> '.join(c)} no longer exists; remove it from EXPLAINED")
            unexplained += 1
    return 1 if unexplained else 0


if __name__ == "__main__":
    sys.exit(main())
