// Shared inputs of the benchmarks and the error report: meshes and the lightning layout.
#pragma once

#include <cmath>

#include <effects/lightning.h>
#include <effects/tangents.h>

namespace bench {

namespace tg = effects::tangents;

// Issue 3's layout: start top-centre, target bottom-centre, no obstacles, eta 2 (the default).
inline effects::lightning::Params lightningLayout(int n, effects::lightning::Method m = effects::lightning::Method::kFast,
                                                  uint64_t seed = 1) {
  effects::lightning::Params p;
  p.width = p.height = n;
  p.start = {n / 2, 0};
  p.targets = {{n / 2, n - 1}};
  p.method = m;
  p.seed = seed;
  return p;
}

// UV sphere: seam and poles included (pole rows without zero-area triangles), normals given.
inline tg::Mesh uvSphere(int rings, int segments) {
  tg::Mesh m;
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s <= segments; ++s) {
      double th = M_PI * r / rings, ph = 2 * M_PI * s / segments;
      double st = r == 0 || r == rings ? 0.0 : std::sin(th);
      glm::vec3 p(float(st * std::cos(ph)), float(std::cos(th)), float(st * std::sin(ph)));
      m.positions.push_back(p);
      m.normals.push_back(p);
      m.uvs.push_back({float(s) / float(segments), 1.0f - float(r) / float(rings)});
    }
  const uint32_t row = uint32_t(segments) + 1;
  for (uint32_t r = 0; r < uint32_t(rings); ++r)
    for (uint32_t s = 0; s < uint32_t(segments); ++s) {
      uint32_t a = r * row + s, b = a + row;
      if (r > 0) m.indices.insert(m.indices.end(), {a, a + 1, b});
      if (r + 1 < uint32_t(rings)) m.indices.insert(m.indices.end(), {a + 1, b + 1, b});
    }
  return m;
}


// A bumpy torus whose UVs are mirrored at u = 1/2 (a mirrored normal map), normals computed.
inline tg::Mesh mirroredTorus(int rings, int segments) {
  tg::Mesh m;
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s <= segments; ++s) {
      double u = 2 * M_PI * s / segments, v = 2 * M_PI * r / rings;
      double tube = 0.35 + 0.04 * std::sin(7 * u) * std::cos(5 * v);
      m.positions.push_back({float((1 + tube * std::cos(v)) * std::cos(u)), float(tube * std::sin(v)),
                             float((1 + tube * std::cos(v)) * std::sin(u))});
      double su = double(s) / segments;
      m.uvs.push_back({float(1 - std::abs(2 * su - 1)), float(double(r) / rings)});
    }
  const uint32_t row = uint32_t(segments) + 1;
  for (uint32_t r = 0; r < uint32_t(rings); ++r)
    for (uint32_t s = 0; s < uint32_t(segments); ++s) {
      uint32_t a = r * row + s, b = a + row;
      m.indices.insert(m.indices.end(), {a, b, a + 1, a + 1, b, b + 1});
    }
  return m;
}

}  // namespace bench
