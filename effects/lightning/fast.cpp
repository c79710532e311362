// The paper's fast method (seed 002 eqns 4-8): Phi_i = a^G / (B * N * P) with no linear
// solve. B (eqn 4, the border and obstacle charges) comes from a cached boundary map, P
// (eqn 5) is the distance to the attractor (or the region), G (eqn 8) the step along the
// axis, N (eqn 6) the bolt cells around the candidate. Each candidate keeps log(a^G / (B P))
// while the axis stands and its Phi^eta against a reference, in a sum tree, so a step redraws
// only the candidates whose N changed, and samples with one uniform draw.
#include <algorithm>
#include <cmath>
#include <limits>

#include "boundary_map.h"
#include "growth.h"
#include "nearest.h"
#include "weight_tree.h"

namespace effects::lightning::detail {

namespace {

class Fast final : public PhiMethod {
 public:
  Fast(Growth& growth, int radius) : s_(growth), p_(growth.p), radius_(radius) {}

  double exponent() const override { return p_.eta; }
  int lifetime() const override { return p_.lifetime; }
  // A new leg of the guide: without a lifetime the frontier left behind (the room before a gap
  // in a wall) would keep candidates that the new axis rewards through the wall. The leg grows
  // from the cells added lately (the paper's lifetime), as DBM's screened field would have it.
  int legLifetime() const override { return p_.lifetime == 0 ? kPaperLifetime : 0; }

  void startRun() override {
    Stopwatch w;
    bool cached = false;
    if (p_.depth) {
      volumeMap_ = cachedBoundary(p_.width, p_.height, p_.depth, p_.obstacles);
      cached = volumeMap_.cached;
    } else {
      boundaryMap_ = cachedBoundary(p_.width, p_.height, p_.obstacles);
      cached = boundaryMap_.cached;
    }
    s_.bolt.stats.counters["boundaryMapMs"] = w.ms();
    s_.bolt.stats.counters["boundaryMapCached"] = cached ? 1 : 0;
    if (!p_.depth) boundaryMemo_ = CellMap<float>(s_.g.cells());
  }
  void startSegment(Cell) override {
    if (s_.toRegion) regionNearest_ = NearestCells(p_.width, p_.height, p_.depth, s_.region);
    rescale_ = true;
  }
  // A new axis: every candidate's G and P change.
  void newLeg() override {
    for (Candidate& c : s_.cands) c.logStatic = logStatic(c);
    rescale_ = true;
  }
  void candidateAdded(Candidate& c) override {
    c.logBoundary = std::log(boundary(c.cell));
    c.logStatic = logStatic(c);
    refreshWeight(c);
  }
  void neighboursChanged(Candidate& c) override { refreshWeight(c); }
  void slotChanged(size_t slot) override { dirty_.push_back(slot); }

  bool drawsItself() const override { return true; }
  size_t draw(Rng& rng) override;
  void logPhi(std::vector<double>& out) override {
    out.resize(s_.cands.size());
    for (size_t i = 0; i < s_.cands.size(); ++i) out[i] = logPhiOf(s_.cands[i]);
  }
  // The setting that ran (calibrate() or the request's own).
  void report(Stats& s) const override {
    s.counters["axisGrowth"] = p_.axisGrowth;
    s.counters["lifetime"] = p_.lifetime;
    s.counters["screeningRadius"] = radius_;
  }

 private:
  double logPhiOf(const Candidate& c) const { return c.logStatic - logN_[size_t(c.neighbours)]; }
  double logStatic(const Candidate& c) const;
  double boundary(Cell c);
  void refreshWeight(Candidate& c);
  void syncWeightTree();

  Growth& s_;
  const Params& p_;
  const int radius_;
  const double lnGrowth_ = std::log(p_.axisGrowth);  // the base of 2^G
  // screening * ln n for the counts 1..26 (26 in a 3-D grid's 26-neighbourhood) or
  // 1..(2 radius_ + 1)^2, looked up (screening 1: the values std::log gives).
  const std::vector<double> logN_ = [s = p_.screening, r = radius_] {
    std::vector<double> t(size_t(std::max(27, (2 * r + 1) * (2 * r + 1))));
    for (size_t i = 1; i < t.size(); ++i) t[i] = s * std::log(double(i));
    return t;
  }();
  NearestCells regionNearest_;  // eqn 5's P towards the region
  CellMap<float> boundaryMemo_;  // 2-D: B per cell once computed (0 = not yet)
  SceneBoundary<BoundaryMap> boundaryMap_;
  SceneBoundary<VolumeBoundary> volumeMap_;  // 3-D
  double weightRef_ = 0;       // weights are exp(eta * log Phi - weightRef_)
  bool rescale_ = true;        // a weight left the safe range; recompute the reference
  WeightTree tree_;            // the candidates' weights, by slot
  std::vector<size_t> dirty_;  // slots whose weight changed since the tree last saw them
  size_t treeUpdates_ = 0;     // since the last rebuild (which also clears rounding drift)
};

double Fast::boundary(Cell c) {
  if (p_.depth) return volumeMap_.potential(c);  // memoised in the maps (up to 128^3)
  const size_t i = s_.g.index(c);
  float memo = boundaryMemo_.get(i);
  if (memo == 0.0f) boundaryMemo_.at(i) = memo = float(boundaryMap_.potential(c));
  return memo;
}

// Seed 002 eqn 8 without N: log(2^G / (B * P)), the base 2 being Params::axisGrowth. B (eqn 4)
// is the border/obstacle charge potential (large near them: Phi small), P (eqn 5) the
// distance to the positive charge, G the candidate's step along anchor -> attractor. N (eqn 6,
// the adjacent bolt cells) changes as the bolt grows and is applied in refreshWeight().
double Fast::logStatic(const Candidate& cand) const {
  const Cell c = cand.cell, anchor = s_.anchor, attractor = s_.attractor;
  double ax = attractor.x - anchor.x, ay = attractor.y - anchor.y, az = attractor.z - anchor.z;
  const double len = p_.depth ? std::hypot(ax, ay, az) : std::hypot(ax, ay);
  if (len > 0) {
    ax /= len;
    ay /= len;
    az /= len;
  }
  // G counts steps towards the attractor and, past it, back: folded at the attractor's
  // distance. Unfolded, 2^G kept rewarding cells beyond the target, and a bolt that
  // overshot in a tall grid ran on to the far wall (128 x 32767: 2 M steps, minutes).
  const double along = p_.depth ? (c.x - anchor.x) * ax + (c.y - anchor.y) * ay + (c.z - anchor.z) * az
                                : (c.x - anchor.x) * ax + (c.y - anchor.y) * ay;
  const double G = std::floor(along <= len ? along : 2 * len - along);
  const double P = s_.towardsRegion ? regionNearest_.distance(c)
                   : p_.depth
                       ? std::hypot(double(c.x - attractor.x), double(c.y - attractor.y), double(c.z - attractor.z))
                       : std::hypot(double(c.x - attractor.x), double(c.y - attractor.y));
  return G * lnGrowth_ - cand.logBoundary - std::log(std::max(P, 0.5));
}

// Phi^eta of one candidate against the current reference (eta = 0: every weight 1).
void Fast::refreshWeight(Candidate& c) {
  if (p_.eta == 0.0) {
    c.weight = 1.0;
    return;
  }
  c.weight = std::exp(p_.eta * logPhiOf(c) - weightRef_);
  if (!(c.weight <= 1e250)) rescale_ = true;
}

// Brings the weight tree up to date: the changed slots one by one, or a rebuild (O(n)) after a
// new reference (every weight changed), when a slot lies beyond the tree, or every n updates
// against rounding drift. The tree is built with room for twice the candidates (zero weights
// past the end), so a growing frontier rebuilds it O(log n) times, not at every step.
void Fast::syncWeightTree() {
  std::vector<Candidate>& cands = s_.cands;
  const bool rescaled = rescale_;
  if (rescaled) {
    double top = -std::numeric_limits<double>::infinity();
    for (const Candidate& c : cands) top = std::max(top, p_.eta * logPhiOf(c));
    weightRef_ = std::isfinite(top) ? top : 0.0;
    rescale_ = false;
    for (Candidate& c : cands) refreshWeight(c);
  }
  bool rebuild =
      rescaled || cands.size() > tree_.size() || treeUpdates_ + dirty_.size() > std::max<size_t>(64, cands.size());
  for (size_t slot : dirty_) rebuild = rebuild || slot >= tree_.size();
  if (rebuild) {
    tree_.rebuild(std::max<size_t>(16, 2 * cands.size()),
                  [&](size_t i) { return i < cands.size() ? cands[i].weight : 0.0; });
    treeUpdates_ = 0;
  } else {
    for (size_t slot : dirty_) tree_.set(slot, slot < cands.size() ? cands[slot].weight : 0.0);
    treeUpdates_ += dirty_.size();
  }
  dirty_.clear();
}

// Samples a candidate with probability Phi_i^eta / sum Phi^eta from the kept weights (one
// uniform draw per step). The reference is reset to the largest eta log Phi whenever a weight
// would overflow or every weight has underflowed; the distribution is the one the Grower
// samples from logPhi.
size_t Fast::draw(Rng& rng) {
  const std::vector<Candidate>& cands = s_.cands;
  const double r = rng.uniform();
  for (int attempt = 0; attempt < 2; ++attempt) {
    syncWeightTree();
    const double total = tree_.total();
    if (total > 0 && std::isfinite(total)) {
      const size_t i = tree_.find(r * total);
      if (i < cands.size() && cands[i].weight > 0) return i;
    }
    rescale_ = true;  // drift or underflow: exact sums from a fresh reference
  }
  for (size_t i = cands.size(); i-- > 0;)  // every Phi = 0: uniform
    if (cands[i].weight > 0) return i;
  return size_t(r * double(cands.size())) % cands.size();
}

}  // namespace

std::unique_ptr<PhiMethod> fastMethod(Growth& growth, int screeningRadius) {
  return std::make_unique<Fast>(growth, screeningRadius);
}

}  // namespace effects::lightning::detail
