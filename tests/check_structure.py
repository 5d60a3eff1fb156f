#!/usr/bin/env python3
"""check_structure.py BUILD_DIR SOURCE_DIR: the dependency structure of the built code.

Reads the symbols of every object file of clothsim's libraries and command
(nm) and fails when
  - a library calls into one it must not know: the direction is
    app -> import, sim, render, common; import -> sim, common;
    sim -> common; render -> common; common -> nothing;
  - source files call each other in a cycle (file A calls a function
    defined in B and B, directly or through others, calls back into A): a
    cycle means neither file can be read, tested or changed alone.
"""
import collections
import glob
import os
import subprocess
import sys

ALLOWED = {
    "common": set(),
    "sim": {"common"},
    "levelset": {"sim", "common"},
    "import": {"sim", "common", "levelset"},
    "render": {"common"},
    "app": {"import", "sim", "render", "common", "levelset"},
}
TARGETS = {"clothsim_common": "common", "clothsim_sim": "sim", "clothsim_levelset": "levelset",
           "clothsim_import": "import", "clothsim_render": "render", "clothsim": "app"}


def objects(build, source):
    """(library, file, object) for every object whose source file still
    exists (a build tree keeps the objects of removed files)."""
    found = []
    for target, lib in TARGETS.items():
        root = os.path.join(build, "CMakeFiles", target + ".dir")
        for path in glob.glob(os.path.join(root, "**", "*.o"), recursive=True):
            name = os.path.relpath(path, root)
            for ext in (".c", ".cpp"):
                if name.endswith(ext + ".o"):
                    name = name[: -len(ext) - 2]
                    if os.path.isfile(os.path.join(source, name + ext)):
                        found.append((lib, name, path))
    return found


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: check_structure.py BUILD_DIR SOURCE_DIR")
    objs = objects(sys.argv[1], sys.argv[2])
    if len(objs) < 20:
        sys.exit("check_structure: found only %d object files under %s" % (len(objs), sys.argv[1]))
    defined, undefined, library = {}, collections.defaultdict(set), {}
    for lib, name, path in objs:
        library[name] = lib
        out = subprocess.run(["nm", path], capture_output=True, text=True, check=True).stdout
        for line in out.splitlines():
            parts = line.split()
            if len(parts) == 3 and parts[1] in "TDBRV":
                defined[parts[2]] = name
            elif len(parts) == 2 and parts[0] == "U":
                undefined[name].add(parts[1])
    edges = collections.defaultdict(dict)
    for name, symbols in undefined.items():
        for sym in symbols:
            target = defined.get(sym)
            if target and target != name:
                edges[name].setdefault(target, []).append(sym)
    problems = []
    for a in sorted(edges):
        for b, syms in sorted(edges[a].items()):
            la, lb = library[a], library[b]
            if la != lb and lb not in ALLOWED[la]:
                problems.append("%s (%s) calls %s (%s): %s" % (a, la, b, lb, ", ".join(sorted(syms))))
    # strongly connected components (Tarjan, iterative)
    index, low, stack, on_stack, cycles, counter = {}, {}, [], set(), [], [0]
    for root in sorted(library):
        if root in index:
            continue
        work = [(root, iter(sorted(edges[root])))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            v, it = work[-1]
            advanced = False
            for w in it:
                if w not in index:
                    index[w] = low[w] = counter[0]
                    counter[0] += 1
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(edges[w]))))
                    advanced = True
                    break
                if w in on_stack:
                    low[v] = min(low[v], index[w])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                component = []
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    component.append(w)
                    if w == v:
                        break
                if len(component) > 1:
                    cycles.append(sorted(component))
    for c in cycles:
        inner = ["%s -> %s (%s)" % (a, b, ", ".join(sorted(edges[a][b])))
                 for a in c for b in sorted(edges[a]) if b in c]
        problems.append("a cycle of %d files: %s\n    %s" % (len(c), " ".join(c), "\n    ".join(inner)))
    print("check_structure: %d object files, %d calls between files" %
          (len(library), sum(len(e) for e in edges.values())))
    if problems:
        print("\n".join(problems))
        sys.exit(1)
    print("check_structure: ok (the libraries' direction holds; no cycle)")


if __name__ == "__main__":
    main()
