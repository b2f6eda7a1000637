#!/usr/bin/env python3
"""Import cycles between the framework's top-level modules (stage folders).

Usage: python3 scripts/module_cycles.py [framework/src]

Every `crate::MODULE` path in a file's code (comments and doc comments excluded,
test modules included) is an edge from the file's top-level module to MODULE.
Prints the dependency list of every module and each strongly connected component
of more than one module (an import cycle); exits 1 when there is one.
"""
import pathlib
import re
import sys

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "framework/src")
edges = {}
for f in sorted(root.rglob("*.rs")):
    rel = f.relative_to(root)
    top = rel.parts[0].removesuffix(".rs")
    if top in ("lib", "main"):
        continue
    code = "\n".join(l.split("//")[0] for l in f.read_text().splitlines())
    deps = edges.setdefault(top, set())
    for m in re.findall(r"\bcrate::(\w+)", code):
        if m != top:
            deps.add(m)

# Tarjan's strongly connected components
index, low, stack, on, sccs, counter = {}, {}, [], set(), [], [0]


def visit(v):
    index[v] = low[v] = counter[0]
    counter[0] += 1
    stack.append(v)
    on.add(v)
    for w in sorted(edges.get(v, ())):
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
        sccs.append(sorted(comp))


sys.setrecursionlimit(10000)
for v in sorted(edges):
    if v not in index:
        visit(v)
for v in sorted(edges):
    print(f"{v:10} -> {', '.join(sorted(edges[v])) or '-'}")
cycles = [c for c in sccs if len(c) > 1]
for c in cycles:
    print("cycle:", " ↔ ".join(c))
print(f"{len(cycles)} cycle(s) between top-level modules")
sys.exit(1 if cycles else 0)
