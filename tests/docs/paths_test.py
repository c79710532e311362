#!/usr/bin/env python3
"""Every repository path a document names exists: backticked or bare paths under the project's
top-level folders (server/, effects/, render/, proto/, tests/, scripts/, bench/, docs/, clients/,
examples/, fixtures/, deploy/, cmake/), with `{h,cpp}` groups expanded and a trailing `:line`
or `#anchor` removed; an include name in angle brackets (`<effects/fog.h>`) is not a path. A
command's output prefix (`docs/x/bubble` for docs/x/bubble-*.png) counts when files start
with it.

  tests/docs/paths_test.py ROOT DOC...     exit 1 naming each path that is not there
"""
import glob
import os
import re
import sys

TOP = "server|effects|render|proto|tests|scripts|bench|docs|clients|examples|fixtures|deploy|cmake"
PATH = re.compile(r"(?<![\w./<-])((?:%s)/[\w./{},*-]*[\w}*])" % TOP)  # not <include/names.h>


def expand(path):
    m = re.search(r"\{([^{}]*)\}", path)
    if not m:
        return [path]
    return [p for alt in m.group(1).split(",") for p in expand(path[:m.start()] + alt + path[m.end():])]


def missing(root, doc):
    text = open(doc, encoding="utf-8").read()
    base = os.path.dirname(os.path.relpath(doc, root))
    bad = []
    for m in PATH.finditer(text):
        for p in expand(m.group(1)):
            p = re.sub(r"[:#].*$", "", p).rstrip(".")
            if "*" in p or "<" in p:
                continue
            if not any(os.path.exists(q) or glob.glob(q + "*") for q in (os.path.join(root, p), os.path.join(root, base, p))):
                bad.append(p)
    return sorted(set(bad))


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    root, failed = sys.argv[1], False
    for doc in sys.argv[2:]:
        for p in missing(root, doc):
            print(f"{doc}: names {p}, which does not exist")
            failed = True
    sys.exit(1 if failed else 0)
