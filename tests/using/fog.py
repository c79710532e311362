#!/usr/bin/env python3
"""docs/using/fog.md, run: its own code (fog_texels, decode, fogged) looks up tables the server
sends, and every fogged colour is checked against the server's per-point answers for the same
points (`samples`: the exact fog at each point, not a table), within the table's own maxError
plus its encoding's rounding. Points lie where maxError is measured (8 per interval, 4 per axis
in 2-D), plus points past the range and the cutoff.

    python3 tests/using/fog.py build/server/effectd
"""
import math
import sys

from page import Checks, Server, page_code

page = page_code("fog")
check = Checks("using_fog")
server = Server(sys.argv[1])
OBJECT = (0.7, 0.2, 0.1)
ROUNDING = {"json": 1e-6, "rgba16f": 2e-3, "rgba8": 1.0 / 255}


def measured_points(table, per_interval):
    """Distances (and ray y) where the server measures maxError: sub-samples of each interval."""
    near, far = table["range"]
    columns, rows = table["size"], table.get("elevations", 1)
    distances = [near + (far - near) * k / (per_interval * (columns - 1)) for k in range(per_interval * (columns - 1) + 1)]
    ys = [-1 + 2 * k / (per_interval * (rows - 1)) for k in range(per_interval * (rows - 1) + 1)] if rows > 1 else [0.0]
    return distances, ys


def compare(name, request, camera, points, rays, color, transmittance_channel=False):
    """Asks for the table and the samples of `points`; checks page.fogged (and the f it looks up)
    against the samples."""
    body = dict(request, include=["table", "samples"], samples={"camera": list(camera), "points": [list(p) for p in points]})
    answer, _ = server.post("/v1/fog", body)
    table = answer["table"]
    texels = page["fog_texels"](table)
    transmittance = page["decode"](table, "transmittanceData") if transmittance_channel else None
    bound = table["maxError"] + ROUNDING[table["encoding"]]
    worst = 0.0
    for p, (distance, ray_y), sample in zip(points, rays, answer["samples"]):
        got = page["fogged"](table, texels, OBJECT, distance, ray_y, transmittance)
        if "transmittance" in sample:   # ATMOSPHERIC: object * T + in-scattered colour, per channel
            want = [t * o + s for t, o, s in zip(sample["transmittance"], OBJECT, sample["fogColor"])]
        else:
            f = sample["factor"]
            want = [f * o + (1 - f) * c for o, c in zip(OBJECT, color)]
        error = max(abs(g - w) for g, w in zip(got, want))
        if distance <= table.get("cutoffDistance", math.inf):  # f itself, from the page's lookup
            f_page = page["sample_linear"](texels, table["size"], table.get("elevations", 1),
                                           *page["fog_uv"](table, distance, ray_y))[3]
            error = max(error, abs(f_page - sample["factor"]))
        past_end = distance > table["range"][1] and "cutoffDistance" not in table
        if not past_end:
            worst = max(worst, error)
        # Past the last column (no cutoff) the page promises 1/255 in f, not maxError.
        if not check(error <= (max(bound, 1.0 / 255 + ROUNDING[table["encoding"]]) if past_end else bound), f"{name}: colour at distance {distance:.4g}, ray y {ray_y:.3g}",
                     f"page {got} vs samples {want}: {error:.3g} > maxError {table['maxError']:.3g} + rounding"):
            break
    print(f"{name}: {len(points)} points, worst {worst:.3g} (maxError {table['maxError']:.3g}, {table['encoding']})")
    return table, answer


def distance_only(name, fog, table_options, extra_distances=()):
    table, _ = server.post("/v1/fog", {"fog": fog, "table": table_options})
    distances, _ = measured_points(table["table"], 8)
    distances += list(extra_distances)
    return compare(name, {"fog": fog, "table": table_options}, (0, 0, 0), [(d, 0, 0) for d in distances],
                   [(d, 0.0) for d in distances], fog.get("color", (1, 1, 1)),
                   transmittance_channel=fog.get("fogType") == "ATMOSPHERIC" and table_options.get("encoding") != "json")


# 1. Seed 003's worked example, a JSON table; past its end the clamped lookup is within 1/255.
worked = {"fogType": "DISTANCE_EXP2", "color": [0.8, 0.8, 0.8], "distanceCoefficient": 0.07}
table, answer = distance_only("DISTANCE_EXP2 json", worked, {"size": 33}, extra_distances=(9.5, 12, 30))
check(abs(table["range"][1] - math.sqrt(math.log(255) / 0.07)) < 1e-9, "the default range ends where f = 1/255",
      table["range"])
# The page's colour at each column equals the server's own finalColors (objectColors).
finals, _ = server.post("/v1/fog", {"fog": worked, "table": {"size": 33}, "objectColors": [list(OBJECT)]})
t = finals["table"]
texels = page["fog_texels"](t)
near, far = t["range"]
for i in range(t["size"]):
    got = page["fogged"](t, texels, OBJECT, near + (far - near) * i / (t["size"] - 1))
    want = t["finalColors"][0][3 * i:3 * i + 3]
    if not check(max(abs(g - w) for g, w in zip(got, want)) < 1e-6, f"column {i}: f*object + S is finalColors", (got, want)):
        break

# 2. The same kind of fog as 8-bit and half-float textures.
distance_only("GL_EXP2 rgba8", {"fogType": "GL_EXP2", "color": [0.6, 0.65, 0.7], "density": 0.05},
              {"size": 48, "encoding": "rgba8"})
distance_only("GL_EXP rgba16f", {"fogType": "GL_EXP", "color": [0.6, 0.65, 0.7], "density": 0.05},
              {"maxError": 0.002, "encoding": "rgba16f"})

# 3. A cutoff: past it the object keeps its colour, as the samples say (f = 1).
cut = {"fogType": "GL_EXP", "color": [0.5, 0.5, 0.55], "density": 0.1, "cutoffDistance": 20}
table, answer = distance_only("GL_EXP with a cutoff", cut, {"size": 32, "encoding": "rgba16f"}, extra_distances=(20.5, 50))
check(table.get("cutoffDistance") == 20 and table["range"][1] == 20, "the table ends at the cutoff and says so", table["range"])
check(answer["samples"][-1]["factor"] == 1.0, "the server does not fog past the cutoff", answer["samples"][-1])

# 4. ATMOSPHERIC: the weight per channel from transmittanceData.
distance_only("ATMOSPHERIC rgba16f", {"fogType": "ATMOSPHERIC", "color": [0.5, 0.6, 0.7],
                                       "extinction": [0.02, 0.04, 0.08], "inscattering": [0.01, 0.02, 0.03]},
              {"size": 256, "encoding": "rgba16f"})

# 5. Height fog, 2-D (the page's example): rows over the ray's y, for a camera at cameraHeight.
height = {"fog": {"fogType": "HEIGHT", "color": [0.7, 0.75, 0.8], "density": 0.05, "heightFalloff": 0.2},
          "table": {"size": 64, "elevations": 16, "cameraHeight": 3, "layout": "linear", "encoding": "rgba16f"}}
table, _ = server.post("/v1/fog", height)
distances, ys = measured_points(table["table"], 4)
camera = (0.0, 3.0, 0.0)
points, rays = [], []
for y in ys:
    for d in distances[::3]:
        horizontal = math.sqrt(max(0.0, 1 - y * y))
        points.append((camera[0] + d * horizontal, camera[1] + d * y, camera[2]))
        rays.append((d, y))
compare("HEIGHT rgba16f, 64 x 16", height, camera, points, rays, height["fog"]["color"])

# 6. A warped HEIGHT table (section 4): example 08's sunset fog at 64 x 32, half floats. The page's
#    lookup against the exact samples at random rays, a third of them near the horizon.
import json
import os
import random
sunset = json.load(open(os.path.join(os.path.dirname(__file__), "..", "..", "examples", "08-sunset-fog.json")))["fog"]["fog"]
camera = (0.0, 1.7, 0.0)
rng = random.Random(47)
points, rays = [], []
for k in range(3000):
    y = rng.uniform(-0.05, 0.05) if k % 3 == 0 else rng.uniform(-1, 1)
    d = rng.uniform(0, 180)
    horizontal = math.sqrt(max(0.0, 1 - y * y))
    points.append([camera[0], camera[1] + d * y, camera[2] - d * horizontal])
    rays.append((d, y))
for encoding in ("json", "rgba16f"):
    request = {"fog": sunset, "table": {"size": 64, "cameraHeight": 1.7, "layout": "warped", "encoding": encoding},
               "include": ["table", "samples"], "samples": {"camera": list(camera), "points": points}}
    answer, _ = server.post("/v1/fog", request)
    table = answer["table"]
    check(table["layout"] == "warped" and table["elevations"] == 32 and table["maxError"] <= 0.01,
          f"warped {encoding}: 64 x 32 meets 0.01", (table.get("elevations"), table["maxError"]))
    texels = page["fog_texels"](table)
    bound = table["maxError"] + ROUNDING[encoding]
    worst = 0.0
    for (d, y), sample in zip(rays, answer["samples"]):
        got = page["fogged_warped"](table, texels, OBJECT, d, y)
        want = [sample["factor"] * o + (1 - sample["factor"]) * c for o, c in zip(OBJECT, sunset["color"])]
        worst = max(worst, max(abs(g - w) for g, w in zip(got, want)))
    check(worst <= bound, f"warped {encoding}: the page's lookup within maxError + rounding",
          f"{worst:.3g} > {bound:.3g}")
    print(f"warped sunset {encoding}: 3000 random rays, worst {worst:.3g} (maxError {table['maxError']:.3g})")
# Without layout the table is the warped one (the default since 2026-11-28); layout linear is the
# old one, far off at the horizon.
default, _ = server.post("/v1/fog", {"fog": sunset, "table": {"size": 64, "cameraHeight": 1.7}})
check(default["table"].get("layout") == "warped" and default["table"]["maxError"] <= 0.01, "no layout: the warped table",
      default["table"]["maxError"])
linear, _ = server.post("/v1/fog", {"fog": sunset, "table": {"size": 64, "elevations": 32, "cameraHeight": 1.7,
                                                             "layout": "linear"}})
check("layout" not in linear["table"] and linear["table"]["maxError"] > 0.4, "layout linear: the linear table",
      linear["table"]["maxError"])

server.close()
check.finish()
