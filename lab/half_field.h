// A candidate law for the fast method (issue 49, item 3), for the bench tools only: Phi_i is the
// Laplace field solved on a grid F times coarser, times local screening by the bolt cells
// around the candidate:
//   log Phi_i = phi * ln PhiC(i) + n1 * ln N1 + n4 * ln(1 + N4) + n3 * ln N3 [+ free * ln E]
// N1: bolt cells among the 8 neighbours, N4: among the 4 edge neighbours, N3: within 3 cells
// (Chebyshev: screening()); E: the candidate's exposure() (lab/exposure_law.h, where the law
// without a field is). lab/lightning_phi_fit.cpp fits the constants to DBM's step
// distribution (the field solved from scratch: CoarseField); lab/lightning_shape.cpp
// (--method half-field) grows bolts by it (the field kept by DBM's incremental solver:
// GrowingCoarseField) and compares their shapes.
// 2-D, 8-neighbourhood, one point target.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include <effects/lightning.h>

#include "lightning/hooks.h"

#include "lightning/deep_field.h"
#include "exposure_law.h"
#include "lightning/solver_choice.h"

namespace bench::shape {

namespace lt = effects::lightning;

// A grid F times coarser than the layout's: a coarse cell is an obstacle where most of it is
// (never the target's), the bolt where a bolt cell lies in it (then never an obstacle).
struct CoarseGrid {
  int F = 2, cw = 0, ch = 0;
  std::vector<uint8_t> obstacles;  // empty: none
  lt::Cell target;

  CoarseGrid(const lt::Params& layout, int factor) : F(factor), cw(layout.width / factor), ch(layout.height / factor) {
    target = at(layout.targets.at(0).x, layout.targets.at(0).y);
    if (layout.obstacles.empty()) return;
    obstacles.assign(size_t(cw) * size_t(ch), 0);
    for (int Y = 0; Y < ch; ++Y)
      for (int X = 0; X < cw; ++X) {
        int blocked = 0;
        for (int y = F * Y; y < F * Y + F; ++y)
          for (int x = F * X; x < F * X + F; ++x)
            blocked += layout.obstacles[size_t(y) * size_t(layout.width) + size_t(x)] != 0;
        obstacles[index({X, Y})] = 2 * blocked > F * F && !(lt::Cell{X, Y} == target);
      }
  }
  lt::Cell at(int x, int y) const { return {std::min(x / F, cw - 1), std::min(y / F, ch - 1)}; }
  size_t index(lt::Cell C) const { return size_t(C.y) * size_t(cw) + size_t(C.x); }
};

// The Laplace field (bolt and obstacles 0, target 1) on a CoarseGrid, read around fine cells.
struct CoarseField {
  CoarseGrid grid;
  std::vector<double> phi;  // per coarse cell

  // Solved from scratch for a bolt (MGPCG).
  CoarseField(const lt::Params& layout, const std::vector<lt::Cell>& bolt, int factor) : grid(layout, factor) {
    std::vector<uint8_t> obstacles = grid.obstacles;
    std::vector<lt::Cell> coarseBolt;
    std::vector<uint8_t> seen(size_t(grid.cw) * size_t(grid.ch), 0);
    for (const lt::Cell& c : bolt) {
      const lt::Cell C = grid.at(c.x, c.y);
      uint8_t& s = seen[grid.index(C)];
      if (s || C == grid.target) continue;
      s = 1;
      if (!obstacles.empty()) obstacles[grid.index(C)] = 0;
      coarseBolt.push_back(C);
    }
    phi = lt::solveLaplace(grid.cw, grid.ch, obstacles, coarseBolt, grid.target, lt::Solver::kMgpcg, 1e-10);
  }
  CoarseField(const CoarseGrid& g, std::vector<double> values) : grid(g), phi(std::move(values)) {}

  // log of the largest field over the fine cell's coarse cell and its 8 neighbours. Where the
  // bolt fills all nine, the candidate is screened at least as deeply as the smallest nonzero
  // field read around any candidate (smallestAround), which it is given.
  double logAround(int x, int y, double smallest) const {
    double v = 0;
    around(x, y, [&](size_t i) { v = std::max(v, phi[i]); });
    return std::log(v > 0 ? v : smallest);
  }
  double smallestAround(const std::vector<lt::Cell>& candidates) const {
    double least = INFINITY;
    for (const lt::Cell& c : candidates)
      around(c.x, c.y, [&](size_t i) {
        if (phi[i] > 0) least = std::min(least, phi[i]);
      });
    return std::isinf(least) ? 1e-300 : least;
  }
  // Calls f with the index of the fine cell's coarse cell and of each of its 8 neighbours.
  template <class F>
  void around(int x, int y, F&& f) const {
    const lt::Cell C = grid.at(x, y);
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        if (C.x + dx >= 0 && C.y + dy >= 0 && C.x + dx < grid.cw && C.y + dy < grid.ch)
          f(grid.index({C.x + dx, C.y + dy}));
  }
};

// The same field kept as the bolt grows, by DBM's own incremental solver on the coarse grid
// (effects/lightning/deep_field.h over the capacitance method: a new fixed cell costs one
// Cholesky row). Private to effects; the bench reaches it as the tests do. Gives the field
// CoarseField gives, to the solver's tolerance.
class GrowingCoarseField {
 public:
  GrowingCoarseField(const lt::Params& layout, int factor)
      : grid_(layout, factor), state_(size_t(grid_.cw) * size_t(grid_.ch), 0) {
    size_t fixed = 1;
    for (uint8_t o : grid_.obstacles) fixed += o;
    field_ = std::make_unique<lt::detail::DeepField>(
        lt::detail::potentialFor(grid_.cw, grid_.ch, 0, lt::Solver::kCapacitance, fixed, fixed), grid_.cw, grid_.ch, 0);
    for (size_t i = 0; i < grid_.obstacles.size(); ++i)
      if (grid_.obstacles[i]) fix(i, kFixedZero, 0.0);
    fix(grid_.index(grid_.target), kTarget, 1.0);
  }
  // A fine bolt cell joined: its coarse cell is the bolt.
  void add(lt::Cell c) {
    const size_t i = grid_.index(grid_.at(c.x, c.y));
    if (state_[i] == kFree) fix(i, kFixedZero, 0.0);  // (an obstacle's or the target's stays)
  }
  // The field at the coarse cells around these fine cells (0 elsewhere: not solved for).
  CoarseField solve(const std::vector<lt::Cell>& around) {
    probes_.clear();
    std::vector<double> phi(state_.size(), 0.0);
    for (const lt::Cell& c : around) {
      const lt::Cell C = grid_.at(c.x, c.y);
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const lt::Cell N{C.x + dx, C.y + dy};
          if (N.x < 0 || N.y < 0 || N.x >= grid_.cw || N.y >= grid_.ch || state_[grid_.index(N)] != kFree) continue;
          state_[grid_.index(N)] = kProbed;
          probes_.push_back(N);
        }
    }
    field_->solve(lt::Solver::kCapacitance, 1e-10, probes_, logPhi_);
    for (size_t k = 0; k < probes_.size(); ++k) {
      phi[grid_.index(probes_[k])] = std::exp(logPhi_[k]);
      state_[grid_.index(probes_[k])] = kFree;
    }
    phi[grid_.index(grid_.target)] = 1.0;
    return CoarseField(grid_, std::move(phi));
  }

 private:
  enum : uint8_t { kFree, kFixedZero, kTarget, kProbed };
  void fix(size_t i, uint8_t state, double value) {
    state_[i] = state;
    field_->fix({int(i % size_t(grid_.cw)), int(i / size_t(grid_.cw))}, value);
  }
  CoarseGrid grid_;
  std::vector<uint8_t> state_;
  std::unique_ptr<lt::detail::DeepField> field_;
  std::vector<lt::Cell> probes_;
  std::vector<double> logPhi_;
};

// The constants (docs/lightning-shape.md, "What a law would have to do"): phi is fitted to DBM's
// single steps (lab/lightning_phi_fit.cpp, open 128^2, eta 2); the screening n1, n4, n3 were
// then set by the shapes of grown bolts at that one layout and eta (single steps gave -0.32,
// -0.25, -0.34, and bolts too bushy). Every other geometry, size and eta is judged held out.
struct HalfFieldLaw {
  double phi = 1.06, n1 = -0.45, n4 = -0.30, n3 = -0.68;
  int coarse = 2;
  double free = 0;  // exponent of the candidate's exposure(); 0: not used
  int reach = 16;
};

// Grows a bolt from p.start until it touches p.targets[0], picking candidate i with probability
// Phi_i^eta / sum_j Phi_j^eta under the law; each node's parent is its latest bolt neighbour.
inline lt::Bolt growHalfField(const lt::Params& p, const HalfFieldLaw& law = {}) {
  const int w = p.width, h = p.height;
  const lt::Cell target = p.targets.at(0);
  auto index = [w](int x, int y) { return size_t(y) * size_t(w) + size_t(x); };
  auto free = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < w && y < h && (p.obstacles.empty() || !p.obstacles[index(x, y)]);
  };
  lt::Bolt bolt;
  std::vector<int> stepAt(size_t(w) * size_t(h), -1), nodeAt(size_t(w) * size_t(h), -1);
  std::vector<lt::Cell> candidates;
  GrowingCoarseField coarse(p, law.coarse);
  std::vector<uint8_t> isCandidate(size_t(w) * size_t(h), 0);
  auto add = [&](lt::Cell c, int parent, int step) {
    nodeAt[index(c.x, c.y)] = int(bolt.nodes.size());
    stepAt[index(c.x, c.y)] = step;
    bolt.nodes.push_back({c, parent, step});
    coarse.add(c);
    isCandidate[index(c.x, c.y)] = 0;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int x = c.x + dx, y = c.y + dy;
        if (!free(x, y) || stepAt[index(x, y)] >= 0 || isCandidate[index(x, y)] || lt::Cell{x, y} == target) continue;
        isCandidate[index(x, y)] = 1;
        candidates.push_back({x, y});
      }
  };
  add(p.start, -1, 0);
  std::mt19937_64 rng(p.seed);
  std::vector<double> logw;
  const Rays rays(law.reach);
  for (int step = 1; size_t(step) < p.maxSteps; ++step) {
    candidates.erase(
        std::remove_if(candidates.begin(), candidates.end(), [&](lt::Cell c) { return !isCandidate[index(c.x, c.y)]; }),
        candidates.end());
    if (candidates.empty()) break;
    const CoarseField field = coarse.solve(candidates);
    const double smallest = field.smallestAround(candidates);
    logw.assign(candidates.size(), 0.0);
    double hi = -INFINITY;
    for (size_t i = 0; i < candidates.size(); ++i) {
      const lt::Cell c = candidates[i];
      const Screening s = screening(stepAt, w, h, c.x, c.y);
      logw[i] = p.eta * (law.phi * field.logAround(c.x, c.y, smallest) + law.n1 * std::log(double(s.n1)) +
                         law.n4 * std::log(1.0 + s.n4) + law.n3 * std::log(double(s.n3)));
      if (law.free != 0) logw[i] += p.eta * law.free * std::log(exposure(stepAt, p.obstacles, w, h, c.x, c.y, rays));
      hi = std::max(hi, logw[i]);
    }
    for (double& v : logw) v = std::exp(v - hi);
    const lt::Cell c = candidates[pickWeighted(
        logw.size(), [&](size_t i) { return logw[i]; }, rng)];
    add(c, latestNeighbour(stepAt, nodeAt, w, h, c), step);
    if (std::abs(c.x - target.x) <= 1 && std::abs(c.y - target.y) <= 1) {
      add(target, int(bolt.nodes.size()) - 1, step + 1);
      break;
    }
  }
  return bolt;
}

}  // namespace bench::shape
