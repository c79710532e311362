# Runs inside Blender (blender -b --factory-startup --python blender_tangents.py -- IN.json OUT.json):
# builds each mesh of IN.json as a Blender mesh (its vertices, triangles, one UV per corner, every
# face smooth), and writes Blender's own vertex normals and its MikkTSpace corner tangents
# (Mesh.calc_tangents: x, y, z and the bitangent sign per corner) to OUT.json. The service is then
# given Blender's normals: custom split normals would be stored quantised per corner, and
# MikkTSpace would stop welding the corners of a vertex.
import json
import sys

import bpy

args = sys.argv[sys.argv.index("--") + 1:]
out = []
for m in json.load(open(args[0])):
    positions, uvs, indices = m["positions"], m["uvs"], m["indices"]
    mesh = bpy.data.meshes.new(m["name"])
    mesh.from_pydata([tuple(positions[3 * i:3 * i + 3]) for i in range(len(positions) // 3)], [],
                     [tuple(indices[t:t + 3]) for t in range(0, len(indices), 3)])
    uv = mesh.uv_layers.new(name="UVMap")
    for loop in mesh.loops:
        uv.data[loop.index].uv = (uvs[2 * loop.index], uvs[2 * loop.index + 1])
    for p in mesh.polygons:
        p.use_smooth = True
    mesh.use_auto_smooth = False
    mesh.calc_tangents(uvmap="UVMap")
    tangents, corners = [], []
    for loop in mesh.loops:
        t = loop.tangent
        tangents += [t.x, t.y, t.z, loop.bitangent_sign]
        corners.append(loop.vertex_index)
    normals = [x for v in mesh.vertices for x in v.normal]
    out.append({"name": m["name"], "loops": len(mesh.loops), "corners": corners, "normals": normals, "tangents": tangents})
json.dump(out, open(args[1], "w"))
