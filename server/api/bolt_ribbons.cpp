#include "api/bolt_ribbons.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace effectd {
namespace {

using nlohmann::json;
namespace lt = effects::lightning;

// The polyline's direction at each vertex: the mean of the segments that meet there (a zero
// segment, two vertices at one point, takes its neighbour's), and each vertex's segment after it.
void directions(const std::vector<glm::dvec3>& p, std::vector<glm::dvec3>& at, std::vector<glm::dvec3>& after) {
  const size_t n = p.size();
  after.assign(n, glm::dvec3(0));
  glm::dvec3 last(1, 0, 0);
  for (size_t i = 0; i + 1 < n; ++i) {
    const glm::dvec3 d = p[i + 1] - p[i];
    const double len = glm::length(d);
    if (len > 1e-12) last = d / len;
    after[i] = last;
  }
  if (n >= 2) after[n - 1] = after[n - 2];
  at.assign(n, glm::dvec3(0));
  for (size_t i = 0; i < n; ++i) {
    const glm::dvec3 sum = i ? after[i - 1] + after[i] : after[i];
    const double len = glm::length(sum);
    at[i] = len > 1e-9 ? sum / len : after[i];  // a full turn back: the segment after
  }
}

// A unit vector at right angles to t.
glm::dvec3 perpendicular(const glm::dvec3& t) {
  const glm::dvec3 axis = std::abs(t.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  return glm::normalize(glm::cross(t, axis));
}

// One ribbon along `p`: at each vertex the pair (p - side*h, p + side*h), v = 0 and 1, where
// h is half the width stretched by the mitre (at most twice, on joins sharper than 120°).
void addRibbon(Ribbons& r, const std::vector<glm::dvec3>& p, const std::vector<glm::dvec3>& side,
               const std::vector<double>& mitre, double halfWidth, const std::vector<double>& along,
               const lt::Polyline& line, const std::vector<double>* leader, const std::vector<double>* strokeDelay) {
  const uint32_t first = uint32_t(r.positions.size() / 3);
  for (size_t i = 0; i < p.size(); ++i) {
    for (int edge = 0; edge < 2; ++edge) {
      const glm::dvec3 q = p[i] + side[i] * ((edge ? 1.0 : -1.0) * halfWidth * mitre[i]);
      r.positions.insert(r.positions.end(), {float(q.x), float(q.y), float(q.z)});
      r.uvs.insert(r.uvs.end(), {float(along[i]), float(edge)});
      r.intensity.push_back(line.vertices[i].intensity);
      if (leader) r.leader.push_back(float((*leader)[i])), r.strokeDelay.push_back(float((*strokeDelay)[i]));
    }
  }
  for (uint32_t k = 0; k + 1 < uint32_t(p.size()); ++k) {
    const uint32_t a = first + 2 * k;
    r.indices.insert(r.indices.end(), {a, a + 1, a + 2, a + 1, a + 3, a + 2});
  }
}

}  // namespace

std::array<Ribbons, 2> boltRibbons(const std::vector<lt::Polyline>& lines, int depth, const World& world,
                                   const lt::Timeline* timeline) {
  std::array<Ribbons, 2> out;
  out[0].main = true;
  World axes = world;
  axes.given = true;  // glTF's axes (y up) with or without a world: origin 0, cell 1 by default
  for (size_t li = 0; li < lines.size(); ++li) {
    const lt::Polyline& line = lines[li];
    if (line.vertices.size() < 2) continue;
    std::vector<glm::dvec3> p;
    for (const auto& v : line.vertices) {
      const auto w = axes.toWorld(v.x, v.y, v.z);
      p.emplace_back(w[0], w[1], w[2]);
    }
    std::vector<glm::dvec3> tangent, after;
    directions(p, tangent, after);
    std::vector<double> along(p.size(), 0.0), mitre(p.size(), 1.0);
    for (size_t i = 1; i < p.size(); ++i) along[i] = along[i - 1] + glm::length(p[i] - p[i - 1]);
    for (size_t i = 0; i < p.size(); ++i) mitre[i] = 1.0 / std::max(0.5, glm::dot(tangent[i], after[i]));
    const double half = 0.5 * line.width * axes.cellSize;
    const std::vector<double>* leader = timeline ? &timeline->leader[li] : nullptr;
    const std::vector<double>* delay = timeline ? &timeline->strokeDelay[li] : nullptr;
    Ribbons& r = out[line.main ? 0 : 1];
    std::vector<glm::dvec3> side(p.size());
    if (!depth) {  // in the plane: the side is the direction turned a quarter about +z
      for (size_t i = 0; i < p.size(); ++i) side[i] = glm::normalize(glm::dvec3(-tangent[i].y, tangent[i].x, 0));
      addRibbon(r, p, side, mitre, half, along, line, leader, delay);
      continue;
    }
    // Parallel transport: each side is the previous one with its component along the new
    // direction removed, so the ribbon does not twist about the polyline.
    side[0] = perpendicular(tangent[0]);
    for (size_t i = 1; i < p.size(); ++i) {
      const glm::dvec3 s = side[i - 1] - glm::dot(side[i - 1], tangent[i]) * tangent[i];
      const double len = glm::length(s);
      side[i] = len > 1e-6 ? s / len : perpendicular(tangent[i]);
    }
    addRibbon(r, p, side, mitre, half, along, line, leader, delay);
    for (size_t i = 0; i < p.size(); ++i) side[i] = glm::cross(tangent[i], side[i]);
    addRibbon(r, p, side, mitre, half, along, line, leader, delay);
  }
  return out;
}

json ribbonsJson(const std::array<Ribbons, 2>& ribbons) {
  json primitives = json::array();
  for (const Ribbons& r : ribbons) {
    if (r.indices.empty()) continue;
    json p = {{"channel", r.main ? "main" : "branch"},
              {"positions", r.positions},
              {"uvs", r.uvs},
              {"intensity", r.intensity},
              {"indices", r.indices}};
    if (!r.leader.empty()) p["leader"] = r.leader, p["strokeDelay"] = r.strokeDelay;
    primitives.push_back(std::move(p));
  }
  return {{"primitives", std::move(primitives)}};
}

}  // namespace effectd
