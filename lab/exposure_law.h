// A candidate law for the fast method with no field solve (issue 49, item 3), for the bench
// tools only. The field's screening by the bolt at a few cells' range is stood in for by the
// candidate's exposure E, its far part by eqn 8's G and P measured around the obstacles:
//   log Phi_i = g * G + p * ln P + n1 * ln N1 + n4 * ln(1 + N4) + n3 * ln N3 + e * ln E
// G = geodesic() at the start less at the candidate (its progress towards the target, as the A*
// guide measures it), P = geodesic() at the candidate (at least 0.5); N1, N4, N3: the bolt cells
// among the 8 neighbours, the 4 edge neighbours and within 3 cells (half_field.h, screening());
// E: exposure(). lab/lightning_phi_fit.cpp fits the constants to DBM's single steps;
// lab/lightning_shape.cpp (--method exposure) grows bolts by growExposureLaw and compares
// their shapes. Results: docs/lightning-shape.md, "What a law would have to do", item 4.
// 2-D, 8-neighbourhood, one point target.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <queue>
#include <random>
#include <type_traits>
#include <utility>
#include <vector>

#include <effects/lightning.h>

namespace bench::shape {

namespace lt = effects::lightning;

// The distance to the target around the obstacles (Dijkstra over 8-neighbour steps 1 and
// sqrt 2); infinite in an obstacle or where the target cannot be reached.
inline std::vector<double> geodesic(const lt::Params& layout) {
  const int w = layout.width, h = layout.height;
  std::vector<double> d(size_t(w) * size_t(h), INFINITY);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> q;
  const lt::Cell t = layout.targets.at(0);
  d[size_t(t.y) * size_t(w) + size_t(t.x)] = 0;
  q.push({0.0, t.y * w + t.x});
  while (!q.empty()) {
    auto [dist, i] = q.top();
    q.pop();
    if (dist > d[size_t(i)]) continue;
    const int x = i % w, y = i / w;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int X = x + dx, Y = y + dy;
        if ((dx == 0 && dy == 0) || X < 0 || Y < 0 || X >= w || Y >= h) continue;
        const size_t j = size_t(Y) * size_t(w) + size_t(X);
        if (!layout.obstacles.empty() && layout.obstacles[j]) continue;
        const double nd = dist + ((dx != 0 && dy != 0) ? M_SQRT2 : 1.0);
        if (nd < d[j]) {
          d[j] = nd;
          q.push({nd, int(j)});
        }
      }
  }
  return d;
}

// The bolt cells around a cell (stepAt[cell] >= 0: the step it joined at).
struct Screening {
  int n1 = 0, n4 = 0, n3 = 0;
  int last = -1;  // the latest step among the 8 neighbours
};
inline Screening screening(const std::vector<int>& stepAt, int w, int h, int x, int y) {
  Screening s;
  for (int dy = -3; dy <= 3; ++dy)
    for (int dx = -3; dx <= 3; ++dx) {
      const int X = x + dx, Y = y + dy;
      if (X < 0 || Y < 0 || X >= w || Y >= h) continue;
      const int step = stepAt[size_t(Y) * size_t(w) + size_t(X)];
      if (step < 0) continue;
      ++s.n3;
      if (std::abs(dx) + std::abs(dy) == 1) ++s.n4;
      if (std::abs(dx) <= 1 && std::abs(dy) <= 1) {
        ++s.n1;
        s.last = std::max(s.last, step);
      }
    }
  return s;
}

// The node a new bolt cell hangs from: its latest bolt neighbour (nodeAt: the node of each bolt
// cell), -1 if none.
inline int latestNeighbour(const std::vector<int>& stepAt, const std::vector<int>& nodeAt, int w, int h, lt::Cell c) {
  int parent = -1, latest = -1;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int x = c.x + dx, y = c.y + dy;
      if (x < 0 || y < 0 || x >= w || y >= h) continue;
      const size_t i = size_t(y) * size_t(w) + size_t(x);
      if (stepAt[i] > latest) latest = stepAt[i], parent = nodeAt[i];
    }
  return parent;
}

// Index i of n with probability weight(i) / sum of the weights.
template <class Weight>
size_t pickWeighted(size_t n, Weight&& weight, std::mt19937_64& rng) {
  double sum = 0;
  for (size_t i = 0; i < n; ++i) sum += weight(i);
  double u = std::uniform_real_distribution<double>(0.0, sum)(rng);
  size_t pick = 0;
  while (pick + 1 < n && u >= weight(pick)) u -= weight(pick++);
  return pick;
}

// 16 rays from a cell, a_k = 2 pi (k + 1/2) / 16: ray k's d-th cell (d = 1 .. reach) is the
// cell plus offset(k, d) = (lround(cos a_k d), lround(sin a_k d)). through() lists the (k, d)
// whose cell is a given offset, so a new bolt cell finds the rays it cuts.
class Rays {
 public:
  static constexpr int kRays = 16;
  explicit Rays(int reach) : reach_(reach), offset_(size_t(kRays) * size_t(reach)), through_(size_t(side() * side())) {
    for (int k = 0; k < kRays; ++k) {
      const double a = 2 * M_PI * (k + 0.5) / kRays;
      for (int d = 1; d <= reach; ++d) {
        const lt::Cell o{int(std::lround(std::cos(a) * d)), int(std::lround(std::sin(a) * d))};
        offset_[size_t(k) * size_t(reach) + size_t(d - 1)] = o;
        through_[slot(o.x, o.y)].push_back({uint8_t(k), uint8_t(d)});
      }
    }
  }
  lt::Cell offset(int k, int d) const { return offset_[size_t(k) * size_t(reach_) + size_t(d - 1)]; }
  const std::vector<std::pair<uint8_t, uint8_t>>& through(int dx, int dy) const { return through_[slot(dx, dy)]; }
  // How many cells ray k travels from (x, y) before one is blocked(X, Y) (at most reach).
  template <class Blocked>
  int march(int k, int x, int y, Blocked&& blocked) const {
    int d = 1;
    for (; d <= reach_; ++d) {
      const lt::Cell o = offset(k, d);
      if (blocked(x + o.x, y + o.y)) break;
    }
    return d - 1;
  }

 private:
  int side() const { return 2 * reach_ + 1; }
  size_t slot(int dx, int dy) const { return size_t(dy + reach_) * size_t(side()) + size_t(dx + reach_); }
  int reach_;
  std::vector<lt::Cell> offset_;
  std::vector<std::vector<std::pair<uint8_t, uint8_t>>> through_;
};

// How exposed a cell is: the mean number of cells its 16 rays travel before they meet a bolt
// cell (stepAt >= 0), an obstacle or the border, at most reach, at least 0.5. A stand-in for
// the field's screening by the bolt at a few cells' range, with no solve.
inline double exposure(const std::vector<int>& stepAt, const std::vector<uint8_t>& obstacles, int w, int h, int x,
                       int y, const Rays& rays) {
  auto blocked = [&](int X, int Y) {
    if (X < 0 || Y < 0 || X >= w || Y >= h) return true;
    const size_t i = size_t(Y) * size_t(w) + size_t(X);
    return stepAt[i] >= 0 || (!obstacles.empty() && obstacles[i]);
  };
  int free = 0;
  for (int k = 0; k < Rays::kRays; ++k) free += rays.march(k, x, y, blocked);
  return std::max(0.5, double(free) / Rays::kRays);
}

// The constants: eta 2's single-step fit on the open 128^2 layout (docs/lightning-shape.md,
// item 4; eta 1's and eta 3's differ there).
struct ExposureLaw {
  double g = 0.0676, p = -1.61, n1 = -0.013, n4 = -0.344, n3 = -0.105, e = 2.02;
  int reach = 16;
};

// Grows a bolt from p.start until it touches p.targets[0], picking candidate i with probability
// Phi_i^eta / sum_j Phi_j^eta under the law; each node's parent is its latest bolt neighbour.
// Every candidate keeps its counts and ray lengths: a new bolt cell updates the candidates
// within reach of it (the counts within 3 cells, the rays that pass through it), and a new
// candidate marches its rays once. `check`, if given, is called after every step with the
// bolt so far (stepAt) and each candidate's cell and kept exposure (the tests compare it with
// exposure() from scratch).
template <class Check = std::nullptr_t>
lt::Bolt growExposureLaw(const lt::Params& p, const ExposureLaw& law = {}, Check&& check = nullptr) {
  const int w = p.width, h = p.height;
  const lt::Cell target = p.targets.at(0);
  auto index = [w](int x, int y) { return size_t(y) * size_t(w) + size_t(x); };
  auto inside = [&](int x, int y) { return x >= 0 && y >= 0 && x < w && y < h; };
  auto obstacle = [&](int x, int y) { return !p.obstacles.empty() && p.obstacles[index(x, y)]; };
  const Rays rays(law.reach);
  const std::vector<double> geo = geodesic(p);
  const double geoStart = geo[index(p.start.x, p.start.y)];
  struct Candidate {
    lt::Cell c;
    int n1 = 0, n4 = 0, n3 = 0, free = 0;
    std::array<uint8_t, Rays::kRays> len{};
    double weight = 0;
  };
  std::vector<Candidate> cands;
  std::vector<int> slot(size_t(w) * size_t(h), -1), stepAt(size_t(w) * size_t(h), -1),
      nodeAt(size_t(w) * size_t(h), -1);
  auto weigh = [&](Candidate& k) {
    const double P = geo[index(k.c.x, k.c.y)];
    const double E = std::max(0.5, double(k.free) / Rays::kRays);
    k.weight = std::exp(p.eta *
                        (law.g * (geoStart - P) + law.p * std::log(std::max(0.5, P)) + law.n1 * std::log(double(k.n1)) +
                         law.n4 * std::log(1.0 + k.n4) + law.n3 * std::log(double(k.n3)) + law.e * std::log(E)));
  };
  auto blocked = [&](int X, int Y) { return !inside(X, Y) || stepAt[index(X, Y)] >= 0 || obstacle(X, Y); };
  lt::Bolt bolt;
  auto add = [&](lt::Cell c, int parent, int step) {
    const size_t ci = index(c.x, c.y);
    nodeAt[ci] = int(bolt.nodes.size());
    stepAt[ci] = step;
    bolt.nodes.push_back({c, parent, step});
    if (slot[ci] >= 0) {  // no longer a candidate: the last takes its slot
      const int s = slot[ci];
      cands[size_t(s)] = cands.back();
      slot[index(cands[size_t(s)].c.x, cands[size_t(s)].c.y)] = s;
      cands.pop_back();
      slot[ci] = -1;
    }
    const int r = law.reach;
    for (int y = std::max(0, c.y - r); y <= std::min(h - 1, c.y + r); ++y)
      for (int x = std::max(0, c.x - r); x <= std::min(w - 1, c.x + r); ++x) {
        const int s = slot[index(x, y)];
        if (s < 0) continue;
        Candidate& k = cands[size_t(s)];
        const int dx = c.x - x, dy = c.y - y;
        bool changed = false;
        if (std::abs(dx) <= 3 && std::abs(dy) <= 3) {
          ++k.n3;
          k.n1 += std::abs(dx) <= 1 && std::abs(dy) <= 1;
          k.n4 += std::abs(dx) + std::abs(dy) == 1;
          changed = true;
        }
        for (const auto& [ray, d] : rays.through(dx, dy))
          if (d <= k.len[ray]) {  // the ray went through c: it stops there now
            k.free -= k.len[ray] - (d - 1);
            k.len[ray] = uint8_t(d - 1);
            changed = true;
          }
        if (changed) weigh(k);
      }
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int x = c.x + dx, y = c.y + dy;
        if (blocked(x, y) || slot[index(x, y)] >= 0 || lt::Cell{x, y} == target) continue;
        Candidate k;
        k.c = {x, y};
        const Screening near = screening(stepAt, w, h, x, y);
        k.n1 = near.n1, k.n4 = near.n4, k.n3 = near.n3;
        for (int ray = 0; ray < Rays::kRays; ++ray)
          k.free += k.len[size_t(ray)] = uint8_t(rays.march(ray, x, y, blocked));
        weigh(k);
        slot[index(x, y)] = int(cands.size());
        cands.push_back(k);
      }
  };
  add(p.start, -1, 0);
  std::mt19937_64 rng(p.seed);
  for (int step = 1; size_t(step) < p.maxSteps && !cands.empty(); ++step) {
    if constexpr (!std::is_same_v<std::decay_t<Check>, std::nullptr_t>)
      for (const Candidate& k : cands) check(stepAt, k.c, std::max(0.5, double(k.free) / Rays::kRays));
    const lt::Cell c = cands[pickWeighted(
                                 cands.size(), [&](size_t i) { return cands[i].weight; }, rng)]
                           .c;
    add(c, latestNeighbour(stepAt, nodeAt, w, h, c), step);
    if (std::abs(c.x - target.x) <= 1 && std::abs(c.y - target.y) <= 1) {
      add(target, int(bolt.nodes.size()) - 1, step + 1);
      break;
    }
  }
  return bolt;
}

}  // namespace bench::shape
