#!/usr/bin/env python3
"""docs/using/lightning.md, run: its own code (to_world, to_grid, vertices, brightness) places
bolts the server grows, and each result is checked against something the page's code did not
compute:
  - the request: every cell inside the grid, outside every obstacle, start first, the target on
    the main channel's last vertex, each cell next to the one it grew from (tree.parent);
  - the server's world units: a 3-D bolt asked with `world` has its points in world units; each
    must lie in the world box of its voxel as the page maps it;
  - the server's ribbons: every JSON mesh vertex lies within the polyline's width of the page's
    polyline in world axes, and the GLB's POSITION, _LEADER and _STROKE_DELAY equal the JSON's;
  - physics: along the main channel strokeDelay is the path to the target over the return
    stroke's speed, and brightness() is dark before the leader and after `duration`.

    python3 tests/using/lightning.py build/server/effectd
"""
import math
import sys

from page import Checks, Glb, Server, page_code

page = page_code("lightning")
check = Checks("using_lightning")
server = Server(sys.argv[1])


def in_obstacles(cell, obstacles):
    if len(cell) == 2:
        return any(x <= cell[0] < x + w and y <= cell[1] < y + h for x, y, w, h in obstacles.get("rects", []))
    return any(x <= cell[0] < x + w and y <= cell[1] < y + h and z <= cell[2] < z + d
               for x, y, z, w, h, d in obstacles.get("boxes", []))


def check_cells(name, request, answer):
    n = len(answer["grid"])
    cells = [tuple(answer["cells"][i:i + n]) for i in range(0, len(answer["cells"]), n)]
    size = [request["grid"]["width"], request["grid"]["height"], request["grid"].get("depth", 1)][:n]
    check(all(0 <= c[a] < size[a] for c in cells for a in range(n)), f"{name}: every cell inside the grid")
    check(not any(in_obstacles(c, request.get("obstacles", {})) for c in cells), f"{name}: no cell in an obstacle")
    check(len(set(cells)) == len(cells), f"{name}: each cell once")
    check(cells[0] == tuple(request["start"]), f"{name}: cell 0 is the start", cells[0])
    parents = answer["tree"]["parent"]
    near = all(max(abs(a - b) for a, b in zip(cells[k], cells[parents[k]])) == 1 for k in range(1, len(cells)))
    check(near, f"{name}: each cell touches the cell it grew from")
    main = [(k, v, p, c) for k, v, p, c in page["vertices"](answer) if k == 0]
    check(tuple(main[-1][3]) == tuple(request["targets"][-1]), f"{name}: the main channel ends at the target", main[-1][3])
    return cells


def inside(point, cell, slack=1e-4):
    return all(c - slack <= x <= c + 1 + slack for x, c in zip(point, cell))


def distance_to_segment(p, a, b):
    ab = [y - x for x, y in zip(a, b)]
    ap = [y - x for x, y in zip(a, p)]
    length2 = sum(c * c for c in ab)
    t = 0.0 if length2 == 0 else max(0.0, min(1.0, sum(x * y for x, y in zip(ab, ap)) / length2))
    return math.dist(p, [x + t * c for x, c in zip(a, ab)])


# 1. A 2-D bolt around an obstacle, jittered: each vertex in its cell; ribbons around the polylines.
request = {"grid": {"width": 64, "height": 64}, "start": [32, 0], "targets": [[20, 63]],
           "obstacles": {"rects": [[8, 30, 40, 3]]}, "seed": 7, "shape": {"jitter": 0.8},
           "include": ["polylines", "cells", "tree", "timeline", "mesh"]}
answer, _ = server.post("/v1/lightning", request)
check_cells("2-D", request, answer)
outside = [(k, v, p, c) for k, v, p, c in page["vertices"](answer) if not inside(p, c)]
check(not outside, "2-D: every polyline vertex lies inside cells[step]", outside[:3])
# The JSON mesh is in world axes with origin 0 and one unit per cell: every ribbon vertex lies
# within the polyline's width (half on each side, mitred joins up to twice that) of it.
world_lines = [[page["to_world"](line["points"][2 * v:2 * v + 2]) for v in range(len(line["step"]))]
               for line in answer["polylines"]]
for primitive in answer["mesh"]["primitives"]:
    lines = [(w, line["width"]) for w, line in zip(world_lines, answer["polylines"])
             if (line["channel"] == "main") == (primitive["channel"] == "main")]
    pos = primitive["positions"]
    worst = max(min(min(distance_to_segment(pos[i:i + 3], w[j], w[j + 1]) for j in range(len(w) - 1)) / width
                    for w, width in lines if len(w) > 1) for i in range(0, len(pos), 3))
    check(worst <= 1.0 + 1e-4, f"2-D mesh {primitive['channel']}: ribbons lie along the page's world polylines",
          f"a vertex {worst:.3f} widths away")

# 2. Timeline: strokeDelay is the return stroke's travel time; the leader descends; dark at the ends.
timeline = answer["timeline"]
cells = answer["cells"]
main_line = answer["polylines"][0]
centres = [[c + 0.5 for c in cells[2 * s:2 * s + 2]] for s in main_line["step"]]
to_target = [sum(math.dist(centres[i], centres[i + 1]) for i in range(v, len(centres) - 1)) for v in range(len(centres))]
speed_per_cell = 25.0 / 1e8  # timeline.cellSize (m) / returnStrokeSpeed (m/s), timeScale 1: the defaults
delays = timeline["polylines"][0]["strokeDelay"]
check(all(abs(d - s * speed_per_cell) <= 1e-12 + 1e-9 * d for d, s in zip(delays, to_target)),
      "strokeDelay = path to the target / return-stroke speed along the main channel")
leaders = timeline["polylines"][0]["leader"]
check(all(a <= b for a, b in zip(leaders, leaders[1:])) and leaders[-1] == timeline["connect"],
      "the leader reaches the main channel's vertices in order and the target at connect")
everything = [(k, v) for k, line in enumerate(answer["polylines"]) for v in range(len(line["step"]))]
check(all(page["brightness"](answer, k, v, -1e-6) == 0 for k, v in everything), "dark before the strike")
check(all(page["brightness"](answer, k, v, timeline["duration"] + 1e-3) < 1e-3 for k, v in everything), "dark after duration")
waiting = [page["brightness"](answer, 0, v, timeline["connect"] + d / 2) for v, d in enumerate(delays) if d > 0]
check(min(waiting) > 0, "a main-channel vertex keeps the leader's glow until the return stroke reaches it", min(waiting))
first = timeline["strokes"][0]
lit = [page["brightness"](answer, 0, v, first["t"] + delays[v] + 1e-4) for v in range(len(delays))]
check(min(lit) > 0.5, "every main-channel vertex is bright just after the first stroke reaches it", min(lit))

# 3. The same bolt as a GLB: the page's parts, equal to the JSON mesh and timeline.
glb_request = dict(request, format="glb", include=["timeline"])
data, headers = server.post("/v1/lightning", glb_request)
glb = Glb(data)
names = [node["name"] for node in glb.doc["nodes"]]
check(names == ["main", "branches"], "GLB nodes main and branches", names)
for mesh, primitive in zip(glb.doc["meshes"], answer["mesh"]["primitives"]):
    attributes = mesh["primitives"][0]["attributes"]
    positions = [x for v in glb.accessor(attributes["POSITION"]) for x in v]
    same = len(positions) == len(primitive["positions"]) and \
        all(abs(a - b) <= 1e-6 * max(1.0, abs(b)) for a, b in zip(positions, primitive["positions"]))
    check(same, f"GLB {mesh['name']}: POSITION is the JSON mesh's (float32)")
    leader = [v[0] for v in glb.accessor(attributes["_LEADER"])]
    check(max(abs(a - b) for a, b in zip(leader, primitive["leader"])) < 1e-6, f"GLB {mesh['name']}: _LEADER is the JSON's leader")
    check("_STROKE_DELAY" in attributes, f"GLB {mesh['name']}: _STROKE_DELAY")
extras = glb.doc["scenes"][0]["extras"]["timeline"]
check(abs(extras["connect"] - timeline["connect"]) < 1e-9 and abs(extras["duration"] - timeline["duration"]) < 1e-9,
      "scenes[0].extras.timeline is the JSON timeline")

# 4. A 3-D bolt placed with `world`: the server's world points lie in the page's world boxes.
origin, cell_size = (-4.0, 12.0, 2.0), 0.5
request3 = {"grid": {"width": 16, "height": 24, "depth": 16}, "start": [8, 0, 8], "targets": [[8, 23, 8]],
            "world": {"origin": list(origin), "cellSize": cell_size}, "obstacles": {"boxes": [[4, 10, 4, 8, 2, 8]]},
            "include": ["polylines", "cells", "tree"], "seed": 3}
answer3, _ = server.post("/v1/lightning", request3)
check_cells("3-D", request3, answer3)
check(answer3["world"] == {"origin": list(origin), "cellSize": cell_size}, "the answer echoes world", answer3["world"])
bad = []
for k, v, p, c in page["vertices"](answer3):
    low, high = page["to_world"](c, origin, cell_size), page["to_world"]([x + 1 for x in c], origin, cell_size)
    if not all(min(a, b) - 1e-4 <= x <= max(a, b) + 1e-4 for x, a, b in zip(p, low, high)) or \
       not inside(page["to_grid"](p, origin, cell_size), c):
        bad.append((k, v, p, c))
check(not bad, "3-D: each world point lies in its voxel's world box", bad[:3])
check(all(line["width"] in (cell_size, 2 * cell_size) for line in answer3["polylines"]), "3-D widths in world units")

server.close()
check.finish()
