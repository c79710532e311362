// Textures generated once per context (the surface wave's normal maps and alpha, the default
// flow pattern), and premultiplication for uploads.
#include <cmath>

#include <glm/geometric.hpp>

#include "gpu.h"

namespace effects::render::detail {

// A tileable height field of integer-frequency waves -> tangent-space normal map (RGBA8).
std::vector<uint8_t> normalMap(int size, uint64_t seed) {
  Rng rng(seed);
  struct Wave {
    double fx, fy, amp, phase;
  };
  std::vector<Wave> waves;
  for (int i = 0; i < 7; ++i) {
    double fx = std::floor(rng.uniform() * 7) - 3, fy = 1 + std::floor(rng.uniform() * 5);
    waves.push_back({fx, fy, 0.05 / std::sqrt(fx * fx + fy * fy), 2 * kPi * rng.uniform()});
  }
  std::vector<uint8_t> out(size_t(size) * size * 4);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      double u = (x + 0.5) / size, v = (y + 0.5) / size, dx = 0, dy = 0;
      for (const Wave& w : waves) {
        double c = std::cos(2 * kPi * (w.fx * u + w.fy * v) + w.phase) * w.amp * 2 * kPi;
        dx += c * w.fx, dy += c * w.fy;
      }
      glm::dvec3 n = glm::normalize(glm::dvec3(-dx, -dy, 1.0));
      uint8_t* p = &out[(size_t(y) * size + x) * 4];
      for (int c = 0; c < 3; ++c) p[c] = uint8_t(std::lround((n[c] * 0.5 + 0.5) * 255));
      p[3] = 255;
    }
  return out;
}

// Smooth tileable single-channel pattern in [0, 1] (the wave's alpha, the flow texture).
std::vector<uint8_t> softPattern(int size, int channels, uint64_t seed, double lo, double hi) {
  Rng rng(seed);
  double f[4][3];
  for (auto& w : f)
    w[0] = 1 + std::floor(rng.uniform() * 4), w[1] = 1 + std::floor(rng.uniform() * 4), w[2] = 2 * kPi * rng.uniform();
  std::vector<uint8_t> out(size_t(size) * size * size_t(channels));
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      double u = double(x) / size, v = double(y) / size;
      for (int c = 0; c < channels; ++c) {
        double s = 0;
        for (int k = 0; k < 4; ++k) s += std::sin(2 * kPi * (f[k][0] * u + f[k][1] * v) + f[k][2] + c * 0.7);
        double t = 0.5 + s / 8.0;  // in [0, 1]
        out[(size_t(y) * size + x) * size_t(channels) + size_t(c)] = uint8_t(std::lround((lo + (hi - lo) * t) * 255));
      }
    }
  return out;
}

std::vector<float> premultiplied(const Image& image) {
  std::vector<float> p = image.rgba;
  for (size_t i = 0; i < p.size(); i += 4)
    for (int c = 0; c < 3; ++c) p[i + size_t(c)] *= p[i + 3];
  return p;
}

}  // namespace effects::render::detail
