#include "api/lightning_volume.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat4x4.hpp>

#include <effects/lightning.h>

#include "api/api_common.h"
#include "contract/codec.h"
#include "api/glb.h"

namespace effectd {
namespace {

using nlohmann::json;

std::array<double, 3> vec3(const json& j) { return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()}; }

// A node's local transform: its matrix, or translation * rotation * scale.
glm::dmat4 localTransform(const json& node) {
  if (node.contains("matrix") && node["matrix"].is_array() && node["matrix"].size() == 16) {
    double m[16];
    for (int i = 0; i < 16; ++i) m[i] = node["matrix"][size_t(i)].is_number() ? node["matrix"][size_t(i)].get<double>() : 0;
    return glm::make_mat4(m);
  }
  auto numbers = [&](const char* key, size_t n, std::array<double, 4> fallback) {
    const json& v = node.contains(key) ? node[key] : json();
    if (v.is_array() && v.size() == n)
      for (size_t i = 0; i < n; ++i) fallback[i] = v[i].is_number() ? v[i].get<double>() : fallback[i];
    return fallback;
  };
  const auto t = numbers("translation", 3, {0, 0, 0, 0}), r = numbers("rotation", 4, {0, 0, 0, 1}),
             s = numbers("scale", 3, {1, 1, 1, 0});
  const glm::dquat q(r[3], r[0], r[1], r[2]);
  return glm::translate(glm::dmat4(1), glm::dvec3(t[0], t[1], t[2])) * glm::mat4_cast(glm::normalize(q)) *
         glm::scale(glm::dmat4(1), glm::dvec3(s[0], s[1], s[2]));
}

// Every triangle of a binary glTF in its scene's coordinates (the default scene, or every root
// node), appended to positions (x, y, z per vertex) and indices.
void glbTriangles(const std::string& bytes, const std::string& at, std::vector<double>& positions,
                  std::vector<uint32_t>& indices) {
  glb::Asset asset;
  auto fail = [&](const FieldError& e) { throw fieldError(400, at + e.pointer, e.message); };
  if (auto e = glb::parse(bytes, asset)) fail(*e);
  const json& g = asset.gltf;
  const json nodes = g.value("nodes", json::array()), meshes = g.value("meshes", json::array());
  std::vector<size_t> roots;
  const json scenes = g.value("scenes", json::array());
  uint64_t sceneIndex = 0;
  if (auto e = glb::unsignedMember(g, "scene", "/scene", 0, scenes.empty() ? 0 : scenes.size() - 1, sceneIndex)) fail(*e);
  if (!scenes.empty()) {
    for (const json& n : scenes[sceneIndex].value("nodes", json::array()))
      if (n.is_number_unsigned() && n.get<uint64_t>() < nodes.size()) roots.push_back(n.get<size_t>());
  } else {
    std::vector<char> child(nodes.size(), 0);
    for (const json& n : nodes)
      for (const json& c : n.value("children", json::array()))
        if (c.is_number_unsigned() && c.get<uint64_t>() < nodes.size()) child[c.get<size_t>()] = 1;
    for (size_t i = 0; i < nodes.size(); ++i)
      if (!child[i]) roots.push_back(i);
  }
  std::vector<char> visited(nodes.size(), 0);  // a node reached twice (a cycle) is an error
  std::function<void(size_t, const glm::dmat4&)> visit = [&](size_t i, const glm::dmat4& parent) {
    const std::string here = "/nodes/" + std::to_string(i);
    if (visited[i]) throw fieldError(400, at + here, "is reached twice in the node hierarchy");
    visited[i] = 1;
    const json& node = nodes[i];
    const glm::dmat4 m = parent * localTransform(node);
    if (node.contains("mesh")) {
      uint64_t mesh = 0;
      if (auto e = glb::unsignedMember(node, "mesh", here + "/mesh", 0, meshes.empty() ? 0 : meshes.size() - 1, mesh))
        fail(*e);
      if (meshes.empty()) throw fieldError(400, at + here + "/mesh", "names a mesh the file does not have");
      const json prims = meshes[mesh].value("primitives", json::array());
      for (size_t p = 0; p < prims.size(); ++p) {
        const std::string pp = "/meshes/" + std::to_string(mesh) + "/primitives/" + std::to_string(p);
        if (prims[p].value("mode", 4) != 4) continue;  // points and lines block nothing
        uint64_t pos = 0;
        if (!prims[p].contains("attributes") || !prims[p]["attributes"].contains("POSITION"))
          throw fieldError(400, at + pp + "/attributes", "has no POSITION");
        if (auto e = glb::unsignedValue(prims[p]["attributes"]["POSITION"], pp + "/attributes/POSITION", 1u << 30, pos))
          fail(*e);
        std::vector<float> xyz;
        if (auto e = glb::readFloats(asset, int(pos), 3, xyz)) fail(*e);
        std::vector<uint32_t> idx;
        if (prims[p].contains("indices")) {
          uint64_t ia = 0;
          if (auto e = glb::unsignedValue(prims[p]["indices"], pp + "/indices", 1u << 30, ia)) fail(*e);
          if (auto e = glb::readIndices(asset, int(ia), idx)) fail(*e);
        } else {
          for (uint32_t k = 0; k < xyz.size() / 3; ++k) idx.push_back(k);
        }
        const uint32_t base = uint32_t(positions.size() / 3);
        for (size_t k = 0; k + 2 < xyz.size(); k += 3) {
          const glm::dvec4 w = m * glm::dvec4(xyz[k], xyz[k + 1], xyz[k + 2], 1.0);
          if (!std::isfinite(w.x) || !std::isfinite(w.y) || !std::isfinite(w.z))
            throw fieldError(400, at + pp + "/attributes/POSITION", "has a position that is not finite");
          positions.insert(positions.end(), {w.x, w.y, w.z});
        }
        for (size_t k = 0; k + 2 < idx.size(); k += 3)
          for (size_t c = 0; c < 3; ++c) {
            if (idx[k + c] >= xyz.size() / 3) throw fieldError(400, at + pp + "/indices", "has an index past the vertices");
            indices.push_back(base + idx[k + c]);
          }
      }
    }
    for (const json& c : node.value("children", json::array()))
      if (c.is_number_unsigned() && c.get<uint64_t>() < nodes.size()) visit(c.get<size_t>(), m);
  };
  for (size_t r : roots) visit(r, glm::dmat4(1));
}

// The triangles in voxel units (positions given in world units with "world"), their work
// bounded: every triangle tests the voxels of its bounding box.
CellShapes::Triangles voxelTriangles(std::vector<double> positions, std::vector<uint32_t> indices, int w, int h, int d,
                                     const World& world, const Config& config, const std::string& field) {
  for (size_t i = 0; i + 2 < positions.size(); i += 3) {
    const auto v = world.toVoxels({positions[i], positions[i + 1], positions[i + 2]});
    positions[i] = v[0], positions[i + 1] = v[1], positions[i + 2] = v[2];
  }
  const size_t work = effects::lightning::voxelizationWork(w, h, d, positions, indices);
  const size_t limit = 8 * config.limits.maxGridCells;
  if (work > limit)
    throw fieldError(413, field,
                     "voxelising the triangles would test " + std::to_string(work) + " voxels; the limit is " +
                         std::to_string(limit) + " (8 x --max-grid-cells)");
  return {std::move(positions), std::move(indices)};
}

}  // namespace

World parseWorld(const json& body) {
  World w;
  if (!body.contains("world")) return w;
  w.given = true;
  const json& o = body["world"];
  if (o.contains("origin")) w.origin = vec3(o["origin"]);
  w.cellSize = o["cellSize"];  // the schema bounds it: (0, 1e6]
  return w;
}

// Long because it is the list of the forms a grid's cells take (rects; boxes, spheres; rows,
// bitmap; mesh, glb), each read and checked in the schema's order.
CellShapes parseCellShapes(const json& o, int w, int h, int d, const World& world, const Config& config,
                           const std::string& at) {
  CellShapes s;
  if (!d) {
    for (const char* threeD : {"boxes", "spheres", "mesh", "glb"})
      if (o.contains(threeD)) throw fieldError(400, at + "/" + threeD, "is for 3-D grids (grid.depth)");
  } else if (o.contains("rects")) {
    throw fieldError(400, at + "/rects", "is for 2-D grids; a 3-D grid takes boxes, spheres, rows, bitmap, mesh or glb");
  }
  const size_t cells = size_t(w) * size_t(h) * size_t(std::max(d, 1));
  // On a 2-D grid an empty list of rects or rows gives no cells (the grid stays open: no guide
  // under guide "auto"); on a 3-D grid, as a bitmap, a mesh or a glb, any form given does.
  if (o.contains("rects")) {
    for (const auto& r : o["rects"]) s.rects.push_back({r[0].get<int>(), r[1].get<int>(), r[2].get<int>(), r[3].get<int>()});
    s.given |= !s.rects.empty();
  }
  if (o.contains("boxes")) {
    for (const auto& b : o["boxes"])
      s.boxes.push_back({b[0].get<int>(), b[1].get<int>(), b[2].get<int>(), b[3].get<int>(), b[4].get<int>(),
                         b[5].get<int>()});
    s.given = true;
  }
  if (o.contains("spheres")) {
    for (const auto& sp : o["spheres"])
      s.spheres.push_back({world.toVoxels(vec3(sp["center"])),
                           sp["radius"].get<double>() / (world.given ? world.cellSize : 1.0)});
    s.given = true;
  }
  if (o.contains("rows")) {
    const json& rows = o["rows"];
    for (size_t i = 0; i < rows.size(); ++i) {
      const std::string row = at + "/rows/" + std::to_string(i);
      if (d && !rows[i].contains("z")) throw fieldError(400, row + "/z", "is required on a 3-D grid");
      CellShapes::Row r{rows[i]["y"].get<int>(), d ? rows[i]["z"].get<int>() : 0, {}};
      if (r.y >= h) throw fieldError(400, row + "/y", "is outside the grid");
      if (!d && rows[i].contains("z")) throw fieldError(400, row + "/z", "is for 3-D grids (grid.depth)");
      if (d && r.z >= d) throw fieldError(400, row + "/z", "is outside the grid");
      for (const auto& run : rows[i]["runs"]) r.runs.push_back({run[0].get<int>(), run[1].get<int>()});
      s.rows.push_back(std::move(r));
    }
    s.given |= d || !rows.empty();
  }
  if (o.contains("bitmap")) {
    auto bytes = base64Decode(o["bitmap"].get<std::string>());
    if (!bytes) throw fieldError(400, at + "/bitmap", "is not valid base64 (standard alphabet, padded)");
    const size_t need = (cells + 7) / 8;
    if (bytes->size() != need)
      throw fieldError(400, at + "/bitmap",
                       "must decode to " + std::to_string(need) + (d ? " bytes (width*height*depth bits), got "
                                                                     : " bytes (width*height bits), got ") +
                           std::to_string(bytes->size()));
    s.bitmap = std::move(*bytes);
    s.given = true;
  }
  if (o.contains("mesh")) {
    const json& m = o["mesh"];
    std::vector<double> positions = m["positions"].get<std::vector<double>>();
    std::vector<uint32_t> indices;
    if (positions.size() % 3) throw fieldError(400, at + "/mesh/positions", "must hold three numbers per vertex");
    if (m["indices"].size() % 3) throw fieldError(400, at + "/mesh/indices", "must hold three indices per triangle");
    for (size_t i = 0; i < m["indices"].size(); ++i) {
      const uint64_t v = m["indices"][i].get<uint64_t>();
      if (v >= positions.size() / 3)
        throw fieldError(400, at + "/mesh/indices/" + std::to_string(i), "is past the last vertex");
      indices.push_back(uint32_t(v));
    }
    s.meshes.push_back(voxelTriangles(std::move(positions), std::move(indices), w, h, d, world, config, at + "/mesh"));
    s.given = true;
  }
  if (o.contains("glb")) {
    auto bytes = base64Decode(o["glb"].get<std::string>());
    if (!bytes) throw fieldError(400, at + "/glb", "is not valid base64 (standard alphabet, padded)");
    std::vector<double> positions;
    std::vector<uint32_t> indices;
    glbTriangles(*bytes, at + "/glb", positions, indices);
    s.meshes.push_back(voxelTriangles(std::move(positions), std::move(indices), w, h, d, world, config, at + "/glb"));
    s.given = true;
  }
  return s;
}

std::vector<uint8_t> drawCellShapes(const CellShapes& s, int w, int h, int d) {
  if (!s.given) return {};
  const int depth = std::max(d, 1);
  std::vector<uint8_t> grid(size_t(w) * size_t(h) * size_t(depth), 0);
  auto index = [&](int x, int y, int z) { return (size_t(z) * size_t(h) + size_t(y)) * size_t(w) + size_t(x); };
  for (const auto& [x0, y0, rw, rh] : s.rects)
    for (int y = y0; y < std::min(h, y0 + rh); ++y)
      for (int x = x0; x < std::min(w, x0 + rw); ++x) grid[index(x, y, 0)] = 1;
  for (const auto& [x0, y0, z0, bw, bh, bd] : s.boxes)
    for (int z = z0; z < std::min(depth, z0 + bd); ++z)
      for (int y = y0; y < std::min(h, y0 + bh); ++y)
        for (int x = x0; x < std::min(w, x0 + bw); ++x) grid[index(x, y, z)] = 1;
  for (const CellShapes::Sphere& sp : s.spheres) {
    const auto& c = sp.center;
    const double r = sp.radius;
    auto range = [&](double centre, int n, int& lo, int& hi) {  // lo > hi: none of the grid
      const double l = std::max(0.0, std::floor(centre - r)), u = std::min(double(n - 1), std::ceil(centre + r));
      lo = u >= l ? int(l) : 1;  // compared first: a centre 1e33 voxels away fits no int
      hi = u >= l ? int(u) : 0;
    };
    int x0, x1, y0, y1, z0, z1;
    range(c[0], w, x0, x1), range(c[1], h, y0, y1), range(c[2], depth, z0, z1);
    for (int z = z0; z <= z1; ++z)
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const double dx = x + 0.5 - c[0], dy = y + 0.5 - c[1], dz = z + 0.5 - c[2];
          if (dx * dx + dy * dy + dz * dz <= r * r) grid[index(x, y, z)] = 1;
        }
  }
  for (const CellShapes::Row& row : s.rows)
    for (const auto& [x0, len] : row.runs)
      for (int x = x0; x < std::min(w, x0 + len); ++x) grid[index(x, row.y, row.z)] = 1;
  if (!s.bitmap.empty())
    for (size_t i = 0; i < grid.size(); ++i)
      if ((uint8_t(s.bitmap[i / 8]) >> (7 - i % 8)) & 1u) grid[i] = 1;
  for (const CellShapes::Triangles& t : s.meshes)
    effects::lightning::voxelizeTriangles(w, h, depth, t.positions, t.indices, grid);
  return grid;
}

}  // namespace effectd
