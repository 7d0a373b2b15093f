#!/usr/bin/env python3
"""The floors of the tree, checked from its includes:

- each module includes headers only of itself and of modules the root
  CMakeLists.txt adds before it (the order of Documentation/Architecture.md);
- no two units (X.h with its X.cpp) include each other, directly or through
  other units: the includes form no cycle. A header without a source of its
  own (a private helper such as Image's ItkImages.h) is no unit to layer: it
  may include the header whose source includes it.

  Tools/check_floors.py [SOURCE_DIR]

Prints each violation and exits 1 if there is one; 0 and a one-line summary
otherwise.
"""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parent.parent)
order = re.findall(r"add_subdirectory\(Modules/(\w+)\)", (root / "CMakeLists.txt").read_text())
rank = {module: i for i, module in enumerate(order)}
include = re.compile(r'#include "(?:dynsub/)?([\w]+)\.h"')

units = {}   # unit name -> module
sources = {}  # unit name -> files
for module in order:
    for path in (root / "Modules" / module).rglob("*"):
        if path.suffix in (".h", ".cpp") and "test" not in path.relative_to(root / "Modules" / module).parts:
            units.setdefault(path.stem, module)
            sources.setdefault(path.stem, []).append(path)

problems = []
edges = {u: set() for u in units}
for unit, files in sources.items():
    for path in files:
        for name in include.findall(path.read_text()):
            if name == unit or name not in units:
                continue
            edges[unit].add(name)
            here, there = units[unit], units[name]
            if rank[there] > rank[here]:
                problems.append(f"{path.relative_to(root)}: {here} includes {name}.h of {there}, "
                                "a module added after it")

# Cycles among units with a source: depth-first search, each cycle reported once.
compiled = {u for u, files in sources.items() if any(f.suffix == ".cpp" for f in files)}
edges = {u: {v for v in e if v in compiled} for u, e in edges.items() if u in compiled}
state, stack = {}, []
def visit(u):
    state[u] = "open"
    stack.append(u)
    for v in sorted(edges[u]):
        if state.get(v) == "open":
            problems.append("include cycle: " + " -> ".join(stack[stack.index(v):] + [v]))
        elif v not in state:
            visit(v)
    stack.pop()
    state[u] = "done"
for u in sorted(edges):
    if u not in state:
        visit(u)

for p in problems:
    print(p)
if problems:
    sys.exit(1)
print(f"floors kept: {len(units)} units in {len(order)} modules, "
      f"{sum(len(e) for e in edges.values())} includes between units, no cycle")
