#!/usr/bin/env python3
"""Writes the generated part of the hostile-input corpus, proto/examples/invalid/g-*.json.

Each file: {endpoint, body | rawBody | rawBodyBase64 | generate, contentType?, expect: {status,
pointer?}}. `generate` builds huge bodies at test time (prefix + repeat * count + suffix) so
that 10 MB strings and 10^5-deep nesting need no 10 MB files. The hand-written cases live
beside these without the g- prefix. Rerun after changing this file; tests/examples_test.cpp
sends every case to a running server.
"""
import base64
import json
import os
import struct
import zlib

OUT = os.path.join(os.path.dirname(__file__), "..", "proto", "examples", "invalid")
cases = {}


# Why the published schema lets a case through (the server refuses it): JSON Schema cannot say it,
# or the limit is a server flag. tests/contract/contract.mjs requires a reason for every such case.
SCHEMA_CANNOT = {
    'bubble-thin-film-over-limit': "limit: width x height against a server flag (--max-thin-film-texels); JSON Schema cannot multiply and the limit is the operator's",
    'lightning-bitmap-bad-padding': 'content: base64 alphabet and padding need `pattern`, outside the keyword subset the server validates with (its decoder checks it)',
    'lightning-bitmap-url-alphabet': 'content: base64 alphabet and padding need `pattern`, outside the keyword subset the server validates with (its decoder checks it)',
    'lightning-bitmap-whitespace': 'content: base64 alphabet and padding need `pattern`, outside the keyword subset the server validates with (its decoder checks it)',
    'lightning-bitmap-wrong-length': 'cross-field: the bitmap must hold width x height bits',
    'lightning-charges-grid-over-solver-limit': "limit: width x height against a server flag (--max-solver-grid-cells); JSON Schema cannot multiply and the limit is the operator's",
    'lightning-dbm-grid-over-solver-limit': "limit: width x height against a server flag (--max-solver-grid-cells); JSON Schema cannot multiply and the limit is the operator's",
    'lightning-everything-blocked': 'geometry: whether a path exists depends on where the obstacles are',
    'lightning-grid-huge-cells': "limit: width x height against a server flag (--max-grid-cells); JSON Schema cannot multiply and the limit is the operator's",
    'lightning-target-outside': 'cross-field: a cell must lie inside grid.width x grid.height',
    'render-flow-texture-garbage': 'content: the decoded PNG or JPEG must be well-formed (the schema sees a string)',
    'render-image-bad-crc': 'content: the decoded PNG or JPEG must be well-formed (the schema sees a string)',
    'render-image-gif': 'content: the decoded PNG or JPEG must be well-formed (the schema sees a string)',
    'render-image-huge-header': 'content: the decoded PNG or JPEG must be well-formed (the schema sees a string)',
    'render-image-not-base64': 'content: base64 alphabet and padding need `pattern`, outside the keyword subset the server validates with (its decoder checks it)',
    'render-image-short-rows': 'content: the decoded PNG or JPEG must be well-formed (the schema sees a string)',
    'render-image-truncated-png': 'content: the decoded PNG or JPEG must be well-formed (the schema sees a string)',
    'render-image-zero-size': 'content: the decoded PNG or JPEG must be well-formed (the schema sees a string)',
    'render-jpeg-truncated': 'content: the decoded PNG or JPEG must be well-formed (the schema sees a string)',
    'render-lightning-unreachable': 'geometry: whether a path exists depends on where the obstacles are',
    'render-near-beyond-far': 'cross-field: camera.far must exceed camera.near',
    'render-up-zero': 'a non-zero vector: needs `not`, outside the keyword subset the server validates with',
    'render-wave-light-zero': 'a non-zero vector: needs `not`, outside the keyword subset the server validates with',
    'scene-lightning-grid-limit': "limit: width x height against a server flag (--max-grid-cells); JSON Schema cannot multiply and the limit is the operator's",
    'tangents-normals-count': 'cross-field: its length must match the number of vertices that positions gives',
    'tangents-positions-empty-indices': 'cross-field: indices must name vertices, and positions has none',
}


def case(name, endpoint, status, pointer=None, **body):
    c = {"endpoint": endpoint}
    c.update(body)
    c["expect"] = {"status": status}
    if pointer is not None:
        c["expect"]["pointer"] = pointer
    if name[2:] in SCHEMA_CANNOT:
        c["schemaCannot"] = SCHEMA_CANNOT[name[2:]]
    assert name not in cases, name
    cases[name] = c


def b64(data):
    return base64.b64encode(data).decode()


def png(width, height, rows=None, crc_ok=True, truncate=None):
    def chunk(kind, data):
        crc = zlib.crc32(kind + data) & 0xFFFFFFFF
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", crc if crc_ok else crc ^ 1)
    raw = rows if rows is not None else b"".join(b"\x00" + b"\x80" * (width * 4) for _ in range(min(height, 4)))
    data = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0))
    data += chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")
    return data[:truncate] if truncate else data


def glb(json_chunk, bin_chunk=b"", magic=b"glTF", version=2, length=None, json_len=None):
    j = json_chunk.encode() if isinstance(json_chunk, str) else json_chunk
    j += b" " * (-len(j) % 4)
    body = struct.pack("<II", json_len if json_len is not None else len(j), 0x4E4F534A) + j
    if bin_chunk:
        bin_chunk += b"\x00" * (-len(bin_chunk) % 4)
        body += struct.pack("<II", len(bin_chunk), 0x004E4942) + bin_chunk
    total = length if length is not None else 12 + len(body)
    return magic + struct.pack("<II", version, total) + body


# ---- every JSON endpoint: malformed bodies ---------------------------------------------------
VALID = {
    "/v1/fog": {"fog": {"fogType": "GL_EXP", "density": 0.1}},
    "/v1/lightning": {"grid": {"width": 16, "height": 16}, "start": [8, 0], "targets": [[8, 15]]},
    "/v1/tangents": {"mesh": {"positions": [0, 0, 0, 1, 0, 0, 0, 1, 0], "uvs": [0, 0, 1, 0, 0, 1], "indices": [0, 1, 2]}},
    "/v1/bubble": {"include": ["uniforms"]},
    "/v1/render": {"width": 32, "height": 32},
    "/v1/scene": {"fog": {"fog": {"fogType": "GL_EXP", "density": 0.1}}},
}
for ep, valid in VALID.items():
    n = ep.split("/")[-1]
    text = json.dumps(valid)
    case(f"g-{n}-truncated", ep, 400, "", rawBody=text[: len(text) // 2])
    case(f"g-{n}-empty-body", ep, 400, "", rawBody="")
    case(f"g-{n}-body-is-string", ep, 400, "", body="hello")
    case(f"g-{n}-body-is-null", ep, 400, "", body=None)
    case(f"g-{n}-unknown-field", ep, 400, "/surprise", body=dict(valid, surprise=1))
    case(f"g-{n}-nan-literal", ep, 400, "", rawBody=text[:-1] + ', "x": NaN}')
    case(f"g-{n}-infinity-literal", ep, 400, "", rawBody=text[:-1] + ', "x": -Infinity}')
    case(f"g-{n}-invalid-utf8", ep, 400, "", rawBodyBase64=b64(text[:-1].encode() + b', "\xff\xfe\xc3": 1}'))
    case(f"g-{n}-lone-surrogate", ep, 400, None, rawBody=text[:-1] + ', "\\ud800": 1}')
    case(f"g-{n}-deep-nesting", ep, 400, "", generate={"prefix": "", "repeat": "[", "count": 100000, "suffix": ""})
    case(f"g-{n}-ten-megabyte-key", ep, 400, None, generate={"prefix": '{"', "repeat": "k", "count": 10 * 1024 * 1024, "suffix": '": 1}'})
    case(f"g-{n}-comment", ep, 400, "", rawBody="/* hi */ " + text)
    case(f"g-{n}-duplicate-then-garbage", ep, 400, "", rawBody=text + text)

# ---- fog -----------------------------------------------------------------------------------------
F = "/v1/fog"
case("g-fog-density-1e308", F, 400, "/fog/density", body={"fog": {"fogType": "GL_EXP", "density": 1e308}})
case("g-fog-ten-megabyte-type", F, 400, "/fog/fogType",
     generate={"prefix": '{"fog": {"fogType": "', "repeat": "A", "count": 10 * 1024 * 1024, "suffix": '"}}'})
case("g-fog-color-two", F, 400, "/fog/color", body={"fog": {"fogType": "GL_EXP", "color": [0.1, 0.2]}})
case("g-fog-color-nested", F, 400, "/fog/color/0", body={"fog": {"fogType": "GL_EXP", "color": [[0.1], 0.2, 0.3]}})
case("g-fog-table-size-zero", F, 400, "/table/size", body={"fog": {"fogType": "GL_EXP"}, "table": {"size": 0}})
case("g-fog-table-size-negative-zero", F, 400, "/table/size", rawBody='{"fog": {"fogType": "GL_EXP"}, "table": {"size": -0.0}}')
case("g-fog-table-size-huge", F, 400, "/table/size", body={"fog": {"fogType": "GL_EXP"}, "table": {"size": 1e18}})
case("g-fog-elevations-negative", F, 400, "/table/elevations", body={"fog": {"fogType": "HEIGHT"}, "table": {"elevations": -3}})
case("g-fog-regions-not-array", F, 400, "/regions", body={"fog": {"fogType": "GL_EXP"}, "regions": {"sphere": {}}})
case("g-fog-region-sphere-missing-radius", F, 400, "/regions/0/sphere/radius",
     body={"fog": {"fogType": "GL_EXP"}, "regions": [{"sphere": {"center": [0, 0, 0]}, "fog": {"fogType": "GL_EXP"}}]})
case("g-fog-samples-points-not-vectors", F, 400, "/samples/points/0",
     body={"fog": {"fogType": "GL_EXP"}, "include": ["samples"], "samples": {"camera": [0, 0, 0], "points": [[1, 2]]}})
case("g-fog-include-not-array", F, 400, "/include", body={"fog": {"fogType": "GL_EXP"}, "include": "table"})
case("g-fog-height-falloff-negative", F, 400, "/fog/heightFalloff", body={"fog": {"fogType": "HEIGHT", "heightFalloff": -1}})
case("g-fog-peak-zero", F, 400, "/fog/peak", body={"fog": {"fogType": "DISTANCE_GAUSSIAN", "peak": 0}})
case("g-fog-encoding-unknown", F, 400, "/table/encoding", body={"fog": {"fogType": "GL_EXP"}, "table": {"encoding": "rgb9e5"}})

# ---- lightning ----------------------------------------------------------------------------------
L = "/v1/lightning"
base = VALID[L]
case("g-lightning-grid-1e308", L, 400, "/grid/width", body=dict(base, grid={"width": 1e308, "height": 16}))
case("g-lightning-grid-negative-zero", L, 400, "/grid/width", rawBody='{"grid": {"width": -0, "height": 16}, "start": [8, 0], "targets": [[8, 15]]}')
case("g-lightning-grid-huge-cells", L, 413, "/grid", body=dict(base, grid={"width": 65536, "height": 65536}))
case("g-lightning-dbm-grid-over-solver-limit", L, 413, "/grid", body=dict(base, grid={"width": 1024, "height": 1024}, method="dbm"))
case("g-lightning-charges-grid-over-solver-limit", L, 413, "/grid", body=dict(base, grid={"width": 512, "height": 512}, method="charges"))
case("g-lightning-targets-empty", L, 400, "/targets", body=dict(base, targets=[]))
case("g-lightning-target-outside", L, 400, "/targets/0", body=dict(base, targets=[[8, 16]]))
case("g-lightning-target-negative", L, 400, "/targets/0/1", body=dict(base, targets=[[8, -1]]))
case("g-lightning-eta-nan-string", L, 400, "/eta", body=dict(base, eta="NaN"))
case("g-lightning-rect-negative", L, 400, "/obstacles/rects/0/0", body=dict(base, obstacles={"rects": [[-1, 0, 2, 2]]}))
case("g-lightning-rect-huge", L, 400, "/obstacles/rects/0/2", body=dict(base, obstacles={"rects": [[0, 0, 1e12, 2]]}))
case("g-lightning-runs-not-pairs", L, 400, "/obstacles/rows/0/runs/0", body=dict(base, obstacles={"rows": [{"y": 3, "runs": [[1, 2, 3]]}]}))
case("g-lightning-bitmap-wrong-length", L, 400, "/obstacles/bitmap", body=dict(base, obstacles={"bitmap": b64(b"\x00" * 31)}))
case("g-lightning-bitmap-bad-padding", L, 400, "/obstacles/bitmap", body=dict(base, obstacles={"bitmap": "AAAA=" }))
case("g-lightning-bitmap-whitespace", L, 400, "/obstacles/bitmap", body=dict(base, obstacles={"bitmap": "AAAA AAAA"}))
case("g-lightning-bitmap-url-alphabet", L, 400, "/obstacles/bitmap", body=dict(base, obstacles={"bitmap": "____" * 8}))
case("g-lightning-everything-blocked", L, 422, None, body=dict(base, obstacles={"rects": [[0, 0, 16, 16]]}))
case("g-lightning-axis-growth-below-one", L, 400, "/axisGrowth", body=dict(base, axisGrowth=0.5))
case("g-lightning-axis-growth-huge", L, 400, "/axisGrowth", body=dict(base, axisGrowth=1e308))
case("g-lightning-max-steps-zero", L, 400, "/maxSteps", body=dict(base, maxSteps=0))
case("g-lightning-shape-falloff-negative", L, 400, "/shape/branchFalloff", body=dict(base, shape={"branchFalloff": -1}))
case("g-lightning-solver-unknown", L, 400, "/solver", body=dict(base, method="dbm", solver="jacobi"))
case("g-lightning-guide-unknown", L, 400, "/guide", body=dict(base, guide="dijkstra"))
case("g-lightning-seed-float", L, 400, "/seed", body=dict(base, seed=1.5))
case("g-lightning-too-many-targets", L, 400, "/targets",
     generate={"prefix": '{"grid": {"width": 16, "height": 16}, "start": [8, 0], "targets": [', "repeat": "[8, 15], ",
               "count": 100000, "suffix": "[8, 15]]}"})

# ---- tangents -----------------------------------------------------------------------------------
T = "/v1/tangents"
mesh = VALID[T]["mesh"]
case("g-tangents-positions-empty-indices", T, 400, "/mesh/indices", body={"mesh": dict(mesh, indices=[0, 1])})
case("g-tangents-index-negative", T, 400, "/mesh/indices/0", body={"mesh": dict(mesh, indices=[-1, 1, 2])})
case("g-tangents-index-huge", T, 400, "/mesh/indices/2", body={"mesh": dict(mesh, indices=[0, 1, 4294967296])})
case("g-tangents-index-float", T, 400, "/mesh/indices/1", body={"mesh": dict(mesh, indices=[0, 1.5, 2])})
case("g-tangents-normals-count", T, 400, "/mesh/normals", body={"mesh": dict(mesh, normals=[0, 0, 1])})
case("g-tangents-position-string", T, 400, "/mesh/positions/0", body={"mesh": dict(mesh, positions=["0"] + mesh["positions"][1:])})
case("g-tangents-position-1e308", T, 400, "/mesh/positions/4", body={"mesh": dict(mesh, positions=[0, 0, 0, 1, 1e308, 0, 0, 1, 0])})
case("g-tangents-missing-uvs", T, 400, "/mesh/uvs", body={"mesh": {"positions": mesh["positions"], "indices": [0, 1, 2]}})
case("g-tangents-uv-origin-unknown", T, 400, "/uvOrigin", body={"mesh": mesh, "uvOrigin": "middle"})
GLB = "model/gltf-binary"
gltf_json = json.dumps({"asset": {"version": "2.0"}, "buffers": [{"byteLength": 36}],
                        "bufferViews": [{"buffer": 0, "byteLength": 36}],
                        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}],
                        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 0}}]}]})
case("g-tangents-glb-wrong-magic", T, 400, None, contentType=GLB, rawBodyBase64=b64(glb(gltf_json, b"\x00" * 36, magic=b"gLTF")))
case("g-tangents-glb-version-1", T, 400, None, contentType=GLB, rawBodyBase64=b64(glb(gltf_json, b"\x00" * 36, version=1)))
case("g-tangents-glb-length-lies", T, 400, None, contentType=GLB, rawBodyBase64=b64(glb(gltf_json, b"\x00" * 36, length=1 << 31)))
case("g-tangents-glb-json-chunk-overflows", T, 400, None, contentType=GLB, rawBodyBase64=b64(glb(gltf_json, b"\x00" * 36, json_len=0xFFFFFFF0)))
case("g-tangents-glb-truncated-header", T, 400, None, contentType=GLB, rawBodyBase64=b64(b"glTF\x02\x00"))
case("g-tangents-glb-json-not-json", T, 400, None, contentType=GLB, rawBodyBase64=b64(glb("{not json", b"\x00" * 36)))
case("g-tangents-glb-accessor-past-buffer", T, 422, None, contentType=GLB,
     rawBodyBase64=b64(glb(gltf_json.replace('"count": 3', '"count": 3000000'), b"\x00" * 36)))
case("g-tangents-glb-no-bin-chunk", T, 422, None, contentType=GLB, rawBodyBase64=b64(glb(gltf_json)))
case("g-tangents-glb-external-uri", T, 422, None, contentType=GLB,
     rawBodyBase64=b64(glb(gltf_json.replace('{"byteLength": 36}', '{"byteLength": 36, "uri": "file:///etc/passwd"}'), b"\x00" * 36)))
case("g-tangents-glb-empty", T, 400, None, contentType=GLB, rawBody="")

# ---- bubble -------------------------------------------------------------------------------------
B = "/v1/bubble"
case("g-bubble-time-1e308", B, 400, "/time", body={"time": 1e308})
case("g-bubble-radius-zero", B, 400, "/mesh/radius", body={"mesh": {"radius": 0}, "include": ["mesh"]})
case("g-bubble-radius-negative-zero", B, 400, "/mesh/radius", rawBody='{"mesh": {"radius": -0.0}, "include": ["mesh"]}')
case("g-bubble-level-negative", B, 400, "/mesh/level", body={"mesh": {"level": -1}, "include": ["mesh"]})
case("g-bubble-wavelengths-two", B, 400, "/thinFilm/wavelengths", body={"thinFilm": {"wavelengths": 2}, "include": ["thinFilm"]})
case("g-bubble-thin-film-over-limit", B, 413, "/thinFilm/width", body={"thinFilm": {"width": 4096, "height": 4096}, "include": ["thinFilm"]})
case("g-bubble-thin-film-width-huge", B, 400, "/thinFilm/width", body={"thinFilm": {"width": 100000}, "include": ["thinFilm"]})
case("g-bubble-motion-s-above-one", B, 400, "/motion/s", body={"motion": {"from": [0, 0, 0], "to": [1, 1, 1], "s": 1.5}})
case("g-bubble-motion-missing-to", B, 400, "/motion/to", body={"motion": {"from": [0, 0, 0], "s": 0.5}})
case("g-bubble-camera-short", B, 400, "/camera", body={"camera": [0, 0], "include": ["mesh"]})
case("g-bubble-feature-string", B, 400, "/features/rim", body={"features": {"rim": "yes"}})
case("g-bubble-shader-language", B, 400, "/shader/language", body={"shader": {"language": "hlsl"}})
case("g-bubble-include-duplicate-unknown", B, 400, "/include/1", body={"include": ["mesh", "everything"]})
case("g-bubble-n1-huge", B, 400, "/params/n1", body={"params": {"n1": 1e300}})

# ---- render and scene ---------------------------------------------------------------------------
R = "/v1/render"
case("g-render-width-negative", R, 400, "/width", body={"width": -5})
case("g-render-width-negative-zero", R, 400, "/width", rawBody='{"width": -0}')
case("g-render-height-float", R, 400, "/height", body={"height": 12.5})
case("g-render-bit-depth-32", R, 400, "/bitDepth", body={"bitDepth": 32})
case("g-render-fov-zero", R, 400, "/camera/fovY", body={"camera": {"fovY": 0}})
case("g-render-near-beyond-far", R, 400, "/camera/far", body={"camera": {"near": 10, "far": 1}})
case("g-render-up-zero", R, 400, "/camera/up", body={"camera": {"up": [0, 0, 0]}})
case("g-render-color-five", R, 400, "/background/color", body={"background": {"color": [0, 0, 0, 1, 1]}})
case("g-render-background-empty", R, 400, "/background", body={"background": {}})
case("g-render-image-not-base64", R, 400, "/background/image", body={"background": {"image": "%%%%"}})
case("g-render-image-gif", R, 400, "/background/image", body={"background": {"image": b64(b"GIF89a\x01\x00\x01\x00")}})
case("g-render-image-truncated-png", R, 400, "/background/image", body={"background": {"image": b64(png(4, 4, truncate=40))}})
case("g-render-image-bad-crc", R, 400, "/background/image", body={"background": {"image": b64(png(4, 4, crc_ok=False))}})
case("g-render-image-huge-header", R, 413, "/background/image", body={"background": {"image": b64(png(100000, 100000, rows=b"\x00"))}})
case("g-render-image-zero-size", R, 400, "/background/image", body={"background": {"image": b64(png(0, 0, rows=b""))}})
case("g-render-image-short-rows", R, 400, "/background/image", body={"background": {"image": b64(png(64, 64, rows=b"\x00" * 10))}})
case("g-render-jpeg-truncated", R, 400, "/background/image", body={"background": {"image": b64(b"\xff\xd8\xff\xe0\x00\x10JFIF\x00")}})
case("g-render-flow-texture-garbage", R, 400, "/bubbleStyle/flowTexture", body={"bubble": {}, "bubbleStyle": {"flowTexture": b64(b"\x89PNG\r\n\x1a\nrest")}})
case("g-render-quads-too-many", R, 400, "/quads", body={"quads": [{"center": [0, 0, 0], "size": [1, 1]}] * 300})
case("g-render-quad-size-zero", R, 400, "/quads/0/size/0", body={"quads": [{"center": [0, 0, 0], "size": [0, 1]}]})
case("g-render-glow-sigma-huge", R, 400, "/lightningStyle/glowSigma",
     body={"lightning": VALID[L], "lightningStyle": {"glowSigma": 1000}})
case("g-render-rect-short", R, 400, "/lightningStyle/rect", body={"lightning": VALID[L], "lightningStyle": {"rect": [0, 0, 1]}})
case("g-render-camera-blend-amount", R, 400, "/cameraBlend/amount", body={"cameraBlend": {"color": [0, 0, 0], "amount": 2}})
case("g-render-wave-light-zero", R, 400, "/surfaceWave/lightDirection", body={"surfaceWave": {"lightDirection": [0, 0, 0]}})
case("g-render-fog-regions-too-many", R, 400, "/fog/regions",
     body={"fog": {"fog": {"fogType": "GL_EXP"}, "regions": [{"sphere": {"center": [0, 0, 0], "radius": 1}, "fog": {"fogType": "GL_EXP"}}] * 17}})
case("g-render-bubble-nested-error", R, 400, "/bubble/params/n2", body={"bubble": {"params": {"n2": 0.5}}})
case("g-render-lightning-unreachable", R, 422, None,
     body={"lightning": dict(VALID[L], obstacles={"rects": [[0, 8, 16, 1]]})})
S = "/v1/scene"
case("g-scene-fog-nested-type", S, 400, "/fog/fog/fogType", body={"fog": {"fog": {"fogType": "FOGGY"}}})
case("g-scene-bubble-level", S, 400, "/bubble/mesh/level", body={"bubble": {"mesh": {"level": 12}, "include": ["mesh"]}})
case("g-scene-lightning-grid-limit", S, 413, "/lightning/grid",
     body={"lightning": dict(VALID[L], grid={"width": 65536, "height": 65536})})

for name in sorted(os.listdir(OUT)):
    if name.startswith("g-"):
        os.remove(os.path.join(OUT, name))
for name, c in cases.items():
    with open(os.path.join(OUT, name + ".json"), "w") as f:
        text = json.dumps(c, indent=1)
        f.write((text if len(text) < 20000 else json.dumps(c, separators=(",", ":"))) + "\n")
print(f"wrote {len(cases)} cases")
