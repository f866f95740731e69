#!/usr/bin/env python3
"""Checks synth/'s #include graph against the CMake stage graph.

Usage: check-layering.py STAGE_GRAPH SYNTH_DIR

STAGE_GRAPH is written by cmake/SolidtexStage.cmake: one line per target, `name|stages|files`.
Every file under SYNTH_DIR must belong to exactly one target, and may include only headers of
its own target or of targets it links (transitively). Exit 1 with one line per violation.
"""
import os
import re
import sys


def main():
    graph_path, synth_dir = sys.argv[1], sys.argv[2]
    deps, owner = {}, {}
    for line in open(graph_path):
        line = line.strip()
        if not line:
            continue
        name, stages, files = line.split("|")
        deps[name] = stages.split()
        for f in files.split():
            owner[f] = name

    def closure(name, seen=None):
        seen = set() if seen is None else seen
        for d in deps.get(name, []):
            if d not in seen:
                seen.add(d)
                closure(d, seen)
        return seen

    problems = []
    for root, _, names in os.walk(synth_dir):
        for n in sorted(names):
            if not n.endswith((".h", ".cpp")):
                continue
            rel = os.path.relpath(os.path.join(root, n), synth_dir)
            if rel not in owner:
                problems.append(f"{rel}: not listed in any stage of synth/CMakeLists.txt")
                continue
            me = owner[rel]
            allowed = closure(me) | {me}
            for lineno, text in enumerate(open(os.path.join(synth_dir, rel)), 1):
                m = re.match(r'\s*#include "([^"]+)"', text)
                if not m:
                    continue
                inc = m.group(1)
                target = owner.get(inc)
                if target is None:
                    problems.append(f"{rel}:{lineno}: includes {inc}, which no stage owns")
                elif target not in allowed:
                    problems.append(f"{rel}:{lineno}: {me} includes {inc} of {target}, which it does not link")
    for p in problems:
        print(p)
    print(f"layering: {len(owner)} files, {len(problems)} violations")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
