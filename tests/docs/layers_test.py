#!/usr/bin/env python3
"""The layers of docs/architecture.md, checked on the sources: includes point one way,
server -> render -> effects, and inside server/ from app/ down to api/, http/, contract/.
The library's private headers (effects/lightning/deep_field.h and the like) stay inside it: the
product above it (render/, server/, bench/) includes its public headers only. Nothing in the
product includes the lab's (lab/).

  tests/docs/layers_test.py ROOT     exit 1 naming each include that points up
"""
import os
import re
import sys

# Lower index = lower layer. A file may include its own layer or a lower one.
SERVER = ["contract", "http", "api", "app"]
INCLUDE = re.compile(r'^\s*#\s*include\s+[<"]([^">]+)[">]', re.M)


def layer_of(path):
    """(top folder, server part) of a source path relative to the root."""
    parts = path.split(os.sep)
    return parts[0], (parts[1] if parts[0] == "server" and len(parts) > 2 else None)


def violations(root):
    bad = []
    private = {d for d in os.listdir(os.path.join(root, "effects"))
               if os.path.isdir(os.path.join(root, "effects", d)) and d != "include"}
    lab = {f for _, _, fs in os.walk(os.path.join(root, "lab")) for f in fs if f.endswith(".h")}
    for top in ("effects", "render", "server", "bench"):
        for d, _, files in os.walk(os.path.join(root, top)):
            for f in files:
                if not f.endswith((".h", ".cpp")):
                    continue
                rel = os.path.relpath(os.path.join(d, f), root)
                owner, part = layer_of(rel)
                for inc in INCLUDE.findall(open(os.path.join(d, f), encoding="utf-8").read()):
                    first = inc.split("/")[0]
                    if owner != "effects" and first in private:
                        bad.append(f"{rel} includes {inc}: the library's private headers are its own")
                    if os.path.basename(inc) in lab and not os.path.exists(os.path.join(d, inc)):
                        bad.append(f"{rel} includes {inc}: the product does not use the lab")
                    if owner == "effects" and (first in ("render", "server") or inc.startswith("effects/render")):
                        bad.append(f"{rel} includes {inc}: effects/ is the bottom layer")
                    if owner == "render" and first in SERVER + ["server"]:
                        bad.append(f"{rel} includes {inc}: render/ may not reach server/")
                    if owner == "server" and first in SERVER:
                        if part is None or SERVER.index(first) > SERVER.index(part):
                            bad.append(f"{rel} includes {inc}: server/{part}/ may include only its own part or one below")
    return bad


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    bad = violations(sys.argv[1])
    for b in bad:
        print(b)
    print(f"{len(bad)} includes point up")
    sys.exit(1 if bad else 0)
