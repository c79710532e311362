"""The request schemas (proto/schemas/*.json) as data: $ref resolution, every property a request
can set, and a request with one property set or removed. Used by tests/schema_truth_test.py
and tests/sweep_test.py."""
import copy
import glob
import json
import os

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
SCHEMAS = {os.path.basename(f): json.load(open(f)) for f in glob.glob(os.path.join(ROOT, "proto/schemas/*.json"))}


def resolve(node, doc):
    """node with its $ref followed (sibling keywords kept), and the file it now lives in."""
    while isinstance(node, dict) and "$ref" in node:
        ref = node["$ref"]
        file, _, frag = ref.partition("#")
        doc = file or doc
        target = SCHEMAS[doc]
        for part in frag.strip("/").split("/") if frag else []:
            target = target[part]
        rest = {k: v for k, v in node.items() if k != "$ref"}
        node = {**target, **rest}
    return node, doc


def properties(node, doc, pointer=""):
    """(pointer, property schema, parent schema) for every property reachable through objects."""
    node, doc = resolve(node, doc)
    for key, sub in node.get("properties", {}).items():
        sub_r, sub_doc = resolve(sub, doc)
        yield pointer + "/" + key, sub_r, node
        if sub_r.get("type") == "object" or "properties" in sub_r:
            yield from properties(sub_r, sub_doc, pointer + "/" + key)


def with_value(base, pointer, value, remove=False):
    """base with the property at pointer set (or removed); parents created as {}; None when a
    parent is not an object (e.g. an array in the example)."""
    body = copy.deepcopy(base)
    node = body
    parts = pointer.strip("/").split("/")
    for part in parts[:-1]:
        if not isinstance(node, dict):
            return None
        node = node.setdefault(part, {})
    if not isinstance(node, dict):
        return None
    if remove:
        node.pop(parts[-1], None)
    else:
        node[parts[-1]] = value
    return body


def examples(endpoint):
    """The valid example requests of an endpoint ("fog", "lightning" ...), sorted by file name."""
    return [json.load(open(f)) for f in sorted(glob.glob(os.path.join(ROOT, "proto/examples", endpoint, "*.json")))]
