#!/usr/bin/env python3
"""Writes examples/model.glb: a small normal-mapped model to try /v1/tangents' glTF path on.

A UV sphere (12 rings x 24 segments, 576 triangles) whose texture is mirrored left/right, as
symmetric game models are: u runs 0 -> 1 over one half of the sphere and back 1 -> 0 over the
other, so MikkTSpace gives the two halves opposite handedness (w = +1 and -1) and splits the
vertices on the two mirror lines. POSITION, NORMAL, TEXCOORD_0 (glTF's top-left UV origin: v = 0
at the north pole), no TANGENT; a material with a checker base colour and a grooved normal map,
both small PNGs embedded in the binary chunk. Written by this script (python3 standard library
only), so it carries no third-party licence.

    python3 scripts/make-model-glb.py [OUT]      (default examples/model.glb)
"""
import json
import math
import os
import struct
import sys
import zlib

RINGS, SEGMENTS = 12, 24


def png(width, height, pixel):
    """An 8-bit RGB PNG; pixel(x, y) -> (r, g, b) in 0..255, row 0 at the top."""
    raw = b"".join(b"\0" + bytes(c for x in range(width) for c in pixel(x, y)) for y in range(height))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def checker(x, y):
    return (230, 200, 120) if (x // 8 + y // 8) % 2 else (60, 90, 160)


def grooves(x, y):
    """Tangent-space normals of horizontal grooves (slope along the image's y), encoded n/2 + 1/2."""
    s = 0.6 * math.sin(2 * math.pi * 4 * (y + 0.5) / 32)
    n = (0.0, s, 1.0)
    length = math.sqrt(sum(c * c for c in n))
    return tuple(round((c / length * 0.5 + 0.5) * 255) for c in n)


def sphere():
    positions, normals, uvs, indices = [], [], [], []
    for i in range(RINGS + 1):
        theta = math.pi * i / RINGS                      # 0 at the north pole (y = +1)
        for j in range(SEGMENTS + 1):
            phi = 2 * math.pi * j / SEGMENTS
            p = (math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi))
            positions += p
            normals += p
            half = j / (SEGMENTS / 2)                     # 0 .. 2 around the sphere
            uvs += (half if half <= 1 else 2 - half, i / RINGS)   # mirrored in u
    row = SEGMENTS + 1
    for i in range(RINGS):
        for j in range(SEGMENTS):
            a, b, c, d = i * row + j, i * row + j + 1, (i + 1) * row + j, (i + 1) * row + j + 1
            if i > 0:
                indices += (a, c, b)                       # counter-clockwise seen from outside
            if i < RINGS - 1:
                indices += (b, c, d)
    return positions, normals, uvs, indices


def glb():
    positions, normals, uvs, indices = sphere()
    parts = [struct.pack(f"<{len(positions)}f", *positions), struct.pack(f"<{len(normals)}f", *normals),
             struct.pack(f"<{len(uvs)}f", *uvs), struct.pack(f"<{len(indices)}H", *indices),
             png(32, 32, checker), png(32, 32, grooves)]
    views, binary = [], b""
    for k, data in enumerate(parts):
        view = {"buffer": 0, "byteOffset": len(binary), "byteLength": len(data)}
        if k < 3:
            view["target"] = 34962
        elif k == 3:
            view["target"] = 34963
        views.append(view)
        binary += data + b"\0" * (-len(data) % 4)
    n = len(positions) // 3
    doc = {
        "asset": {"version": "2.0", "generator": "effectd scripts/make-model-glb.py"},
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "name": "sphere"}],
        "meshes": [{"name": "sphere", "primitives": [{
            "attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": 0}]}],
        "materials": [{"name": "grooved", "pbrMetallicRoughness": {
            "baseColorTexture": {"index": 0}, "metallicFactor": 0.0, "roughnessFactor": 0.6},
            "normalTexture": {"index": 1}}],
        "textures": [{"source": 0, "sampler": 0}, {"source": 1, "sampler": 0}],
        "samplers": [{"magFilter": 9729, "minFilter": 9729}],
        "images": [{"bufferView": 4, "mimeType": "image/png"}, {"bufferView": 5, "mimeType": "image/png"}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3",
             "min": [min(positions[c::3]) for c in range(3)], "max": [max(positions[c::3]) for c in range(3)]},
            {"bufferView": 1, "componentType": 5126, "count": n, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": n, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5123, "count": len(indices), "type": "SCALAR"}],
        "bufferViews": views,
        "buffers": [{"byteLength": len(binary)}],
    }
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    body = struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(binary), b"BIN\0") + binary
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.normpath(os.path.join(os.path.dirname(__file__), "..", "examples", "model.glb"))
    data = glb()
    with open(out, "wb") as f:
        f.write(data)
    print(f"{out}: {len(data)} bytes")
