// Laplacian growth: the three ways of getting Phi (fast, dbm, charges), candidate sampling,
// the A* guide, chain targets, and the per-step error against the converged Laplace solution.
// Over 500 lines because it is one class, the Grower, whose steps share the growth state
// (bolt, candidates, their weights, the axis); its pure parts live beside it (grid.h,
// laplace.h, astar, weight_tree.h).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include "deep_field.h"
#include "grid.h"
#include "laplace.h"
#include "nearest.h"
#include "potential.h"
#include "weight_tree.h"

namespace effects::lightning {

std::optional<Error> validate(const Params& p) {
  // Each side named as the HTTP API names it (its schema's bounds).
  for (const auto& [side, pointer] : {std::pair{p.width, "/grid/width"}, std::pair{p.height, "/grid/height"}}) {
    if (side < 3) return invalid(pointer, "must be >= 3");
    if (side > 65536) return overLimit(pointer, "must be <= 65536");
    if (p.depth && side > 4096) return overLimit(pointer, "must be <= 4096 in a 3-D grid");
  }
  if (p.depth != 0 && (p.depth < 3 || p.depth > 4096)) return invalid("/grid/depth", "must be 0 (2-D) or in [3, 4096]");
  const size_t cells = size_t(p.width) * size_t(p.height) * size_t(std::max(p.depth, 1));
  if (!p.obstacles.empty() && p.obstacles.size() != cells)
    return invalid("/obstacles", p.depth ? "must have width*height*depth cells" : "must have width*height cells");
  if (!(p.eta >= 0.0 && p.eta <= 50.0)) return invalid("/eta", "must be in [0, 50]");
  if (!(p.axisGrowth >= 1.0 && p.axisGrowth <= 64.0)) return invalid("/axisGrowth", "must be in [1, 64]");
  if (!(p.screening >= 0.0 && p.screening <= 8.0)) return invalid("/screening", "must be in [0, 8]");
  if (!(p.chargesEta >= 0.0 && p.chargesEta <= 50.0)) return invalid("/chargesEta", "must be in [0, 50]");
  if (p.screeningRadius < 0 || p.screeningRadius > 7) return invalid("/screeningRadius", "must be in [0, 7]");
  if (p.lifetime < 0) return invalid("/lifetime", "must be >= 0 (0 = candidates never expire)");
  if (!(p.tolerance >= 1e-12 && p.tolerance <= 1e-1)) return invalid("/tolerance", "must be in [1e-12, 0.1]");
  if (p.targets.empty() && p.targetRegion.empty())
    return invalid("/targets", "needs at least one target or a targetRegion");
  if (!p.targetRegion.empty() && p.targetRegion.size() != cells)
    return invalid("/targetRegion", p.depth ? "must have width*height*depth cells" : "must have width*height cells");
  if (p.depth == 0 && p.neighbourhood != 4 && p.neighbourhood != 8)
    return invalid("/neighbourhood", "must be 4 or 8 on a 2-D grid");
  if (p.depth && p.neighbourhood != 6 && p.neighbourhood != 26)
    return invalid("/neighbourhood", "must be 6 or 26 on a 3-D grid");
  if (p.depth && p.method == Method::kCharges) return invalid("/method", "charges is 2-D only; use fast or dbm");
  return std::nullopt;
}

namespace {

using detail::Grid;

constexpr double kNegInf = -std::numeric_limits<double>::infinity();

struct Candidate {
  Cell cell;
  int born;        // step at which it last gained a bolt neighbour
  int neighbours;  // N of seed 002 eqn 6: adjacent bolt cells, 1..8 (1..4 in a 4-neighbourhood, 1..26 in
                   // 3-D); with a screening radius r > 1, the bolt cells within r (1..(2r+1)^2)
  int parent;      // node it attaches to if chosen: its newest bolt neighbour
  double charge;   // kCharges: sum over bolt cells of 1/r
  // kFast: log(2^G / (B * P)), fixed while the segment's axis stands, and Phi^eta relative
  // to the grower's weight reference (kept per candidate: only cells that gain a neighbour
  // change, so a step costs one pass of additions, not a logarithm and a power per candidate).
  double logStatic = 0, weight = 0;
  double logBoundary = 0;  // kFast: log B, which no new axis changes
};

class Grower {
 public:
  Grower(const Params& p, Bolt& bolt)
      : p_(p),
        g_{p.width, p.height, &p.obstacles, std::max(p.depth, 1)},
        stencil_(detail::stencil(p.neighbourhood)),
        bolt_(bolt) {
    const size_t cells = g_.cells();
    nodeOf_ = detail::CellIndex(cells);
    candidateOf_ = detail::CellIndex(cells);
    reserved_ = detail::CellMap<uint8_t>(cells);
    if (radius_ > 1) near_ = detail::CellMap<uint8_t>(cells);
    for (const Cell& t : p.targets)
      if (g_.inside(t.x, t.y, t.z)) reserved_.at(g_.index(t)) = 1;
    if (!p.targetRegion.empty()) {  // the region less the obstacles, reserved like targets
      region_.assign(cells, 0);
      for (size_t i = 0; i < cells; ++i)
        if (p.targetRegion[i] && (p.obstacles.empty() || !p.obstacles[i])) region_[i] = reserved_.at(i) = 1;
    }
  }

  std::optional<Error> run();

 private:
  // Free for growth: inside, no obstacle, not bolt, not a target still to be reached (those
  // join the bolt only when it touches them).
  bool free(int x, int y, int z) const {
    if (!g_.inside(x, y, z) || g_.blocked(x, y, z)) return false;
    size_t i = g_.index(x, y, z);
    return nodeOf_.get(i) < 0 && !reserved_.get(i);
  }
  int addNode(Cell c, int parent);
  void addCandidatesAround(int node);
  void removeCandidate(size_t slot);
  void expireCandidates();
  void logWeights(std::vector<double>& out);
  double fastLogStatic(const Candidate& c) const;
  double fastLogPhi(const Candidate& c) const { return c.logStatic - logN_[size_t(c.neighbours)]; }
  void screenAround(Cell c);
  void refreshFastWeight(Candidate& c);
  void restartFastWeights();
  size_t sampleFast();
  void syncWeightTree();
  void markWeight(size_t slot) {
    if (p_.method == Method::kFast) dirty_.push_back(slot);
  }
  double boundary(Cell c);
  std::optional<Error> growSegment(size_t k);
  std::vector<Cell> guidePath(size_t k, Cell fromCell, Cell target);
  std::unique_ptr<detail::DeepField> dbmProblem(Cell target, Solver solver) const;
  bool inRegion(int x, int y, int z) const { return g_.inside(x, y, z) && region_[g_.index(x, y, z)]; }
  // The segment's end is in reach of c: its target touches c, or (toRegion_) a region cell does.
  bool reached(Cell c, Cell target) const;
  Cell regionCellTouching(Cell c) const;
  const std::vector<Cell>& candidateCells();
  void reviveFrontier(int from, size_t segmentFirstNode);
  void weighCandidates(std::vector<double>& logPhi);
  void followWaypoints(Cell newest, const std::vector<Cell>& waypoints, size_t& wp);
  double stepError(const std::vector<double>& logPhi);

  bool touching(Cell a, Cell b) const { return detail::touching(a, b, p_.neighbourhood); }

  const Params& p_;
  Grid g_;
  std::vector<uint8_t> region_;         // Params::targetRegion less the obstacles (empty: none)
  detail::NearestCells regionNearest_;  // kFast: eqn 5's P towards the region
  bool toRegion_ = false;               // the segment grows to the region
  bool towardsRegion_ = false;          // ... and its axis ends on it (P = distance to the region)
  detail::Stencil stencil_;
  Bolt& bolt_;
  detail::CellIndex nodeOf_, candidateOf_;
  detail::CellMap<uint8_t> reserved_;
  std::vector<Candidate> cands_;
  detail::CellMap<float> boundaryMemo_;  // kFast 2-D: B per cell once computed (0 = not yet)
  detail::SceneBoundary<detail::BoundaryMap> boundaryMap_;
  detail::SceneBoundary<detail::VolumeBoundary> volumeMap_;  // 3-D
  std::unique_ptr<detail::DeepField> laplace_, reference_;
  std::vector<Cell> probes_;       // the candidates' cells, for DeepField::solve
  std::vector<double> dbmLogPhi_;  // kDbm: their log Phi from it
  Rng rng_{p_.seed};
  const double lnGrowth_ = std::log(p_.axisGrowth);  // kFast: the base of 2^G
  // The power the candidates' Phi is raised to: eta, or for kCharges the charges exponent.
  const double exponent_ = p_.method != Method::kCharges ? p_.eta
                           : p_.chargesEta > 0           ? p_.chargesEta
                                                         : calibratedChargesEta(p_);
  // kFast: N counted within radius_ (1: the adjacent cells), and screening * ln n for the
  // counts 1..26 (26 in a 3-D grid's 26-neighbourhood) or 1..(2 radius_ + 1)^2, looked up
  // (screening 1: the values std::log gives).
  const int radius_ = screeningRadius(p_);
  const std::vector<double> logN_ = [s = p_.screening, r = radius_] {
    std::vector<double> t(size_t(std::max(27, (2 * r + 1) * (2 * r + 1))));
    for (size_t i = 1; i < t.size(); ++i) t[i] = s * std::log(double(i));
    return t;
  }();
  detail::CellMap<uint8_t> near_;  // radius_ > 1: bolt cells within radius_ of each cell (<= 15^2)
  int step_ = 0;
  Cell anchor_, attractor_;    // current sub-bolt axis: anchor -> attractor (seed 002 eqn 8's G)
  double weightRef_ = 0;       // kFast: weights are exp(eta * log Phi - weightRef_)
  bool rescale_ = true;        // kFast: a weight left the safe range; recompute the reference
  detail::WeightTree tree_;    // kFast: the candidates' weights, by slot
  std::vector<size_t> dirty_;  // kFast: slots whose weight changed since the tree last saw them
  size_t treeUpdates_ = 0;     // since the last rebuild (which also clears rounding drift)
  double solverIterations_ = 0, lastResidual_ = 0, errorSum_ = 0;
  size_t directSteps_ = 0, iterativeSteps_ = 0;  // kDbm: steps solved by each kind of solver
  int errorSteps_ = 0;
  double errorMs_ = 0;  // the reference's solves: not the method's time
  size_t candidatesMax_ = 0;
};

// A new bolt cell screens every cell within radius_: their counts rise, candidates among them
// are weighed again.
void Grower::screenAround(Cell c) {
  for (int y = std::max(0, c.y - radius_); y <= std::min(p_.height - 1, c.y + radius_); ++y)
    for (int x = std::max(0, c.x - radius_); x <= std::min(p_.width - 1, c.x + radius_); ++x) {
      const size_t i = g_.index(x, y, 0);
      ++near_.at(i);
      if (const int32_t slot = candidateOf_.get(i); slot >= 0) {
        Candidate& cand = cands_[size_t(slot)];
        cand.neighbours = near_.get(i);
        refreshFastWeight(cand);
        markWeight(size_t(slot));
      }
    }
}

int Grower::addNode(Cell c, int parent) {
  int id = int(bolt_.nodes.size());
  bolt_.nodes.push_back({c, parent, step_});
  nodeOf_.set(g_.index(c), id);
  if (int slot = candidateOf_.get(g_.index(c)); slot >= 0) removeCandidate(size_t(slot));
  if (radius_ > 1) screenAround(c);
  if (laplace_) laplace_->fix(c, 0.0);
  if (reference_) reference_->fix(c, 0.0);
  if (p_.method == Method::kCharges) {  // Kim et al. 2007: one new term per candidate
    for (auto& cand : cands_) cand.charge += 1.0 / std::hypot(double(cand.cell.x - c.x), double(cand.cell.y - c.y));
  }
  return id;
}

void Grower::removeCandidate(size_t slot) {
  candidateOf_.set(g_.index(cands_[slot].cell), -1);
  if (slot + 1 != cands_.size()) {
    cands_[slot] = cands_.back();
    candidateOf_.set(g_.index(cands_[slot].cell), int32_t(slot));
  }
  markWeight(slot);
  markWeight(cands_.size() - 1);
  cands_.pop_back();
}

void Grower::addCandidatesAround(int node) {
  Cell c = bolt_.nodes[size_t(node)].cell;
  for (int k = 0; k < stencil_.size; ++k) {
    int x = c.x + stencil_.dx[k], y = c.y + stencil_.dy[k], z = c.z + stencil_.dz[k];
    if (!free(x, y, z)) continue;
    size_t i = g_.index(x, y, z);
    if (const int32_t slot = candidateOf_.get(i); slot >= 0) {
      Candidate& cand = cands_[size_t(slot)];
      cand.born = step_;
      cand.parent = node;
      if (radius_ == 1) {  // with a wider radius, screenAround() has counted and weighed it
        cand.neighbours = std::min(cand.neighbours + 1, stencil_.size);
        if (p_.method == Method::kFast) refreshFastWeight(cand);
      }
      markWeight(size_t(slot));
      continue;
    }
    Candidate cand{{x, y, z}, step_, radius_ > 1 ? int(near_.get(i)) : 0, node, 0.0};
    if (radius_ == 1)
      for (int j = 0; j < stencil_.size; ++j) {
        int nx = x + stencil_.dx[j], ny = y + stencil_.dy[j], nz = z + stencil_.dz[j];
        if (g_.inside(nx, ny, nz) && nodeOf_.get(g_.index(nx, ny, nz)) >= 0) ++cand.neighbours;
      }
    if (p_.method == Method::kCharges)
      for (const Node& n : bolt_.nodes) cand.charge += 1.0 / std::hypot(double(x - n.cell.x), double(y - n.cell.y));
    if (p_.method == Method::kFast) {
      cand.logBoundary = std::log(boundary(cand.cell));
      cand.logStatic = fastLogStatic(cand);
      refreshFastWeight(cand);
    }
    candidateOf_.set(i, int32_t(cands_.size()));
    cands_.push_back(cand);
    markWeight(cands_.size() - 1);
  }
  candidatesMax_ = std::max(candidatesMax_, cands_.size());
}

void Grower::expireCandidates() {
  // Seed 002: a candidate older than the lifetime is dropped, bounding the candidate set.
  if (p_.method != Method::kFast || p_.lifetime == 0) return;
  for (size_t i = cands_.size(); i-- > 0;)
    if (step_ - cands_[i].born > p_.lifetime) removeCandidate(i);
}

double Grower::boundary(Cell c) {
  if (p_.depth) return volumeMap_.potential(c);  // memoised in the maps (up to 128^3)
  const size_t i = g_.index(c);
  float memo = boundaryMemo_.get(i);
  if (memo == 0.0f) boundaryMemo_.at(i) = memo = float(boundaryMap_.potential(c));
  return memo;
}

// log of Phi_i for every candidate (-inf where Phi_i = 0).
void Grower::logWeights(std::vector<double>& out) {
  out.resize(cands_.size());
  switch (p_.method) {
    case Method::kFast:
      for (size_t i = 0; i < cands_.size(); ++i) out[i] = fastLogPhi(cands_[i]);
      break;
    case Method::kDbm:
      out = dbmLogPhi_;  // DeepField::solve's, for the candidates in order
      break;
    case Method::kCharges: {
      // Kim et al. 2007: phi_i = sum_j (1 - R1/r_ij), R1 = h/2, with the target as the positive
      // charge paired with every bolt charge: phi_i = R1 * sum_j (1/r_it - 1/r_ij), then
      // normalised to [0, 1] over the candidates.
      const double R1 = 0.5, n = double(bolt_.nodes.size());
      double lo = INFINITY, hi = -INFINITY;
      for (size_t i = 0; i < cands_.size(); ++i) {
        const Candidate& c = cands_[i];
        double rt = std::max(0.5, std::hypot(double(c.cell.x - attractor_.x), double(c.cell.y - attractor_.y)));
        out[i] = R1 * (n / rt - c.charge);
        lo = std::min(lo, out[i]);
        hi = std::max(hi, out[i]);
      }
      for (double& v : out) v = hi > lo ? std::log((v - lo) / (hi - lo)) : 0.0;
      break;
    }
  }
}

// Seed 002 eqn 8 without N: log(2^G / (B * P)), the base 2 being Params::axisGrowth. B (eqn 4)
// is the border/obstacle charge potential (large near them: Phi small), P (eqn 5) the
// distance to the positive charge, G the candidate's step along anchor -> attractor. N (eqn 6,
// the adjacent bolt cells) changes as the bolt grows and is applied in refreshFastWeight().
double Grower::fastLogStatic(const Candidate& cand) const {
  const Cell c = cand.cell;
  double ax = attractor_.x - anchor_.x, ay = attractor_.y - anchor_.y, az = attractor_.z - anchor_.z;
  const double len = p_.depth ? std::hypot(ax, ay, az) : std::hypot(ax, ay);
  if (len > 0) {
    ax /= len;
    ay /= len;
    az /= len;
  }
  // G counts steps towards the attractor and, past it, back: folded at the attractor's
  // distance. Unfolded, 2^G kept rewarding cells beyond the target, and a bolt that
  // overshot in a tall grid ran on to the far wall (128 x 32767: 2 M steps, minutes).
  const double along = p_.depth ? (c.x - anchor_.x) * ax + (c.y - anchor_.y) * ay + (c.z - anchor_.z) * az
                                : (c.x - anchor_.x) * ax + (c.y - anchor_.y) * ay;
  const double G = std::floor(along <= len ? along : 2 * len - along);
  const double P = towardsRegion_ ? regionNearest_.distance(c)
                   : p_.depth
                       ? std::hypot(double(c.x - attractor_.x), double(c.y - attractor_.y), double(c.z - attractor_.z))
                       : std::hypot(double(c.x - attractor_.x), double(c.y - attractor_.y));
  return G * lnGrowth_ - cand.logBoundary - std::log(std::max(P, 0.5));
}

// Phi^eta of one candidate against the current reference (eta = 0: every weight 1).
void Grower::refreshFastWeight(Candidate& c) {
  if (p_.eta == 0.0) {
    c.weight = 1.0;
    return;
  }
  c.weight = std::exp(p_.eta * fastLogPhi(c) - weightRef_);
  if (!(c.weight <= 1e250)) rescale_ = true;
}

// A new axis (segment start, next waypoint): every candidate's G and P change.
void Grower::restartFastWeights() {
  for (Candidate& c : cands_) c.logStatic = fastLogStatic(c);
  rescale_ = true;
}

// Brings the weight tree up to date: the changed slots one by one, or a rebuild (O(n)) after a
// new reference (every weight changed), when a slot lies beyond the tree, or every n updates
// against rounding drift. The tree is built with room for twice the candidates (zero weights
// past the end), so a growing frontier rebuilds it O(log n) times, not at every step.
void Grower::syncWeightTree() {
  const bool rescaled = rescale_;
  if (rescaled) {
    double top = kNegInf;
    for (const Candidate& c : cands_) top = std::max(top, p_.eta * fastLogPhi(c));
    weightRef_ = std::isfinite(top) ? top : 0.0;
    rescale_ = false;
    for (Candidate& c : cands_) refreshFastWeight(c);
  }
  bool rebuild =
      rescaled || cands_.size() > tree_.size() || treeUpdates_ + dirty_.size() > std::max<size_t>(64, cands_.size());
  for (size_t slot : dirty_) rebuild = rebuild || slot >= tree_.size();
  if (rebuild) {
    tree_.rebuild(std::max<size_t>(16, 2 * cands_.size()),
                  [&](size_t i) { return i < cands_.size() ? cands_[i].weight : 0.0; });
    treeUpdates_ = 0;
  } else {
    for (size_t slot : dirty_) tree_.set(slot, slot < cands_.size() ? cands_[slot].weight : 0.0);
    treeUpdates_ += dirty_.size();
  }
  dirty_.clear();
}

// Samples a candidate with probability Phi_i^eta / sum Phi^eta from the kept weights (one
// uniform draw per step). The reference is reset to the largest eta log Phi whenever a weight
// would overflow or every weight has underflowed; the distribution is candidateWeights()'.
size_t Grower::sampleFast() {
  const double r = rng_.uniform();
  for (int attempt = 0; attempt < 2; ++attempt) {
    syncWeightTree();
    const double total = tree_.total();
    if (total > 0 && std::isfinite(total)) {
      const size_t i = tree_.find(r * total);
      if (i < cands_.size() && cands_[i].weight > 0) return i;
    }
    rescale_ = true;  // drift or underflow: exact sums from a fresh reference
  }
  for (size_t i = cands_.size(); i-- > 0;)  // every Phi = 0: uniform
    if (cands_[i].weight > 0) return i;
  return size_t(r * double(cands_.size())) % cands_.size();
}

// Unnormalised p_i = Phi_i^eta (seed 002 eqn 2) from log Phi, scaled by the largest so that
// nothing overflows; eta = 0 or all Phi = 0 gives uniform weights (0^0 = 1). Returns the sum.
double candidateWeights(const std::vector<double>& logPhi, double eta, std::vector<double>& w) {
  w.resize(logPhi.size());
  double top = kNegInf;
  for (double l : logPhi) top = std::max(top, l);
  double sum = 0;
  for (size_t i = 0; i < logPhi.size(); ++i) {
    w[i] = (eta == 0.0 || top == kNegInf) ? 1.0 : std::exp(eta * (logPhi[i] - top));
    sum += w[i];
  }
  return sum;
}

// Samples index i with probability Phi_i^eta / sum Phi^eta.
size_t sample(const std::vector<double>& logPhi, double eta, Rng& rng, std::vector<double>& w) {
  double u = rng.uniform() * candidateWeights(logPhi, eta, w);
  for (size_t i = 0; i < w.size(); ++i) {
    u -= w[i];
    if (u < 0) return i;
  }
  size_t last = w.size() - 1;
  while (last > 0 && w[last] == 0) --last;
  return last;
}

double Grower::stepError(const std::vector<double>& logPhi) {
  // Total-variation distance between this method's candidate distribution and the one the
  // converged Laplace solution gives on the same bolt state (over all free bolt neighbours).
  std::vector<double> p;
  const double pSum = candidateWeights(logPhi, exponent_, p);
  for (double& v : p) v /= pSum;
  // Reference support: every free cell next to a bolt cell.
  std::vector<size_t> cells;
  for (const Node& n : bolt_.nodes)
    for (int k = 0; k < stencil_.size; ++k) {
      int x = n.cell.x + stencil_.dx[k], y = n.cell.y + stencil_.dy[k], z = n.cell.z + stencil_.dz[k];
      if (free(x, y, z)) cells.push_back(g_.index(x, y, z));
    }
  std::sort(cells.begin(), cells.end());
  cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
  probes_.resize(cells.size());
  for (size_t k = 0; k < cells.size(); ++k) probes_[k] = g_.cellAt(cells[k]);
  std::vector<double> refLogPhi, refPhi;
  reference_->solve(Solver::kMgpcg, 1e-10, probes_, refLogPhi);
  const double refSum = candidateWeights(refLogPhi, p_.eta, refPhi);  // the weights
  double tv = 0;
  std::vector<double> mine(cells.size(), 0.0);
  double outside = 0;  // probability this method puts outside the reference support (none in practice)
  for (size_t i = 0; i < cands_.size(); ++i) {
    auto it2 = std::lower_bound(cells.begin(), cells.end(), g_.index(cands_[i].cell));
    if (it2 != cells.end() && *it2 == g_.index(cands_[i].cell))
      mine[size_t(it2 - cells.begin())] += p[i];
    else
      outside += p[i];
  }
  for (size_t k = 0; k < cells.size(); ++k) tv += std::fabs(mine[k] - refPhi[k] / refSum);
  return 0.5 * (tv + outside);
}

// The path from the segment's start to its target on the grid with the bolt so far blocked,
// except the start: empty when the target cannot be reached. Its turns guide the growth.
std::vector<Cell> Grower::guidePath(size_t k, Cell fromCell, Cell target) {
  // The first segment searches the obstacles as they are (no copy), unless a target region
  // (which only its own segment may enter) lies in its way.
  const bool copy = k > 0 || (!region_.empty() && !toRegion_);
  std::vector<uint8_t> withBolt;
  if (copy) {
    withBolt = p_.obstacles;
    if (withBolt.empty()) withBolt.assign(g_.cells(), 0);
    for (const Node& n : bolt_.nodes) withBolt[g_.index(n.cell)] = 1;
    if (!toRegion_)
      for (size_t i = 0; i < region_.size(); ++i) withBolt[i] |= region_[i];
    withBolt[g_.index(fromCell)] = 0;
  }
  const std::vector<uint8_t>& blocked = copy ? withBolt : p_.obstacles;
  Stopwatch guideWatch;
  std::vector<Cell> path =
      toRegion_ ? astarToRegion(p_.width, p_.height, blocked, fromCell, region_, p_.neighbourhood, p_.depth)
                : astar(p_.width, p_.height, blocked, fromCell, target, p_.neighbourhood, p_.depth);
  bolt_.stats.counters["guideMs"] += guideWatch.ms();
  return path;
}

// The DBM problem of a segment: bolt so far, obstacles (and outside) at 0, target (or the
// whole region) at 1, on the solver potential.h chooses.
std::unique_ptr<detail::DeepField> Grower::dbmProblem(Cell target, Solver solver) const {
  size_t fixedCells = bolt_.nodes.size() + 1;
  for (uint8_t o : p_.obstacles) fixedCells += o != 0;
  if (toRegion_)
    for (uint8_t r : region_) fixedCells += r;
  std::unique_ptr<detail::Potential> lap =
      detail::potentialFor(p_.width, p_.height, p_.depth, solver, fixedCells, fixedCells);  // room to grow
  auto field = std::make_unique<detail::DeepField>(std::move(lap), p_.width, p_.height, p_.depth);
  for (size_t i = 0; i < g_.cells(); ++i)
    if (!p_.obstacles.empty() && p_.obstacles[i]) field->fix(g_.cellAt(i), 0.0);
  for (const Node& n : bolt_.nodes) field->fix(n.cell, 0.0);
  if (!toRegion_) field->fix(target, 1.0);
  for (size_t i = 0; toRegion_ && i < region_.size(); ++i)
    if (region_[i]) field->fix(g_.cellAt(i), 1.0);
  return field;
}

bool Grower::reached(Cell c, Cell target) const {
  if (!toRegion_) return touching(c, target);
  for (int k = 0; k < stencil_.size; ++k)
    if (inRegion(c.x + stencil_.dx[k], c.y + stencil_.dy[k], c.z + stencil_.dz[k])) return true;
  return false;
}

// The region cell a bolt cell strikes: of the region cells touching it, the nearest (a face
// before an edge before a corner), the first in stencil order among equals.
Cell Grower::regionCellTouching(Cell c) const {
  Cell best = c;
  int bestD = 4;
  for (int k = 0; k < stencil_.size; ++k) {
    const int dx = stencil_.dx[k], dy = stencil_.dy[k], dz = stencil_.dz[k];
    const int d = dx * dx + dy * dy + dz * dz;
    if (d < bestD && inRegion(c.x + dx, c.y + dy, c.z + dz)) {
      best = {c.x + dx, c.y + dy, c.z + dz};
      bestD = d;
    }
  }
  return best;
}

const std::vector<Cell>& Grower::candidateCells() {
  probes_.resize(cands_.size());
  for (size_t i = 0; i < cands_.size(); ++i) probes_[i] = cands_[i].cell;
  return probes_;
}

// Every candidate expired or the sub-bolt is boxed in: the candidates around the segment's
// start and every node it added come back.
void Grower::reviveFrontier(int from, size_t segmentFirstNode) {
  bolt_.stats.counters["revivals"] += 1;
  addCandidatesAround(from);
  for (size_t n = segmentFirstNode; n < bolt_.nodes.size(); ++n) addCandidatesAround(int(n));
}

// log Phi of every candidate for this step (after the DBM solve), and its error against the
// converged solution when measured.
void Grower::weighCandidates(std::vector<double>& logPhi) {
  if (laplace_) {
    solverIterations_ += laplace_->solve(p_.solver, p_.tolerance, candidateCells(), dbmLogPhi_);
    (laplace_->direct() ? directSteps_ : iterativeSteps_) += 1;
  }
  logWeights(logPhi);
  if (reference_) {
    Stopwatch w;
    errorSum_ += stepError(logPhi);
    ++errorSteps_;
    errorMs_ += w.ms();
  }
}

// Seed 002 section 3.2: move on to the next waypoint early when the newest bolt cell is next
// to the current one or sees the next one.
void Grower::followWaypoints(Cell newest, const std::vector<Cell>& waypoints, size_t& wp) {
  while (wp + 1 < waypoints.size() &&
         (touching(newest, waypoints[wp]) || detail::lineOfSight(g_, newest, waypoints[wp + 1]))) {
    anchor_ = newest;
    attractor_ = waypoints[++wp];
    towardsRegion_ = toRegion_ && wp + 1 == waypoints.size();
    if (p_.method == Method::kFast) {
      // A new leg of the guide: without a lifetime the frontier left behind (the room before
      // a gap in a wall) would keep candidates that the new axis rewards through the wall.
      // The leg grows from the cells added lately (the paper's lifetime), as DBM's screened
      // field would have it.
      if (p_.lifetime == 0)
        for (size_t i = cands_.size(); i-- > 0;)
          if (step_ - cands_[i].born > kPaperLifetime) removeCandidate(i);
      restartFastWeights();
    }
  }
}

std::optional<Error> Grower::growSegment(size_t k) {
  toRegion_ = k == p_.targets.size();  // the last segment, when a region is given
  const Cell target = toRegion_ ? Cell{} : p_.targets[k];
  const int from = k == 0 ? 0 : int(bolt_.nodes.size()) - 1;  // previous target's node
  const std::string field = toRegion_ ? "/targetRegion" : "/targets/" + std::to_string(k);
  const Cell fromCell = bolt_.nodes[size_t(from)].cell;

  // Reachability (and the guide) with the bolt so far blocked, except the segment's start.
  std::vector<Cell> path = guidePath(k, fromCell, target);
  if (path.empty())
    return unsatisfiable(
        field, std::string(toRegion_ ? "no cell of the region is reachable" : "target is unreachable") + " from " +
                   (k ? "the previous target" : "start"));
  const bool useGuide =
      p_.method != Method::kDbm && (p_.guide == Guide::kAstar || (p_.guide == Guide::kAuto && !p_.obstacles.empty()));
  // Towards a region, the axis (and fast's eqn 8) aims at the region's cell the search reached.
  std::vector<Cell> waypoints = useGuide ? detail::turningPoints(path) : std::vector<Cell>{path.back()};
  if (useGuide) bolt_.guide.insert(bolt_.guide.end(), waypoints.begin(), waypoints.end());
  size_t wp = 0;
  anchor_ = fromCell;
  attractor_ = waypoints[0];
  towardsRegion_ = toRegion_ && waypoints.size() == 1;
  if (toRegion_ && p_.method == Method::kFast)
    regionNearest_ = detail::NearestCells(p_.width, p_.height, p_.depth, region_);
  if (p_.method == Method::kDbm) laplace_ = dbmProblem(target, p_.solver);
  if (p_.measureError) {
    Stopwatch w;
    reference_ = dbmProblem(target, Solver::kMgpcg);
    errorMs_ += w.ms();
  }

  // Chain lightning: the new segment grows from the previous target only.
  for (size_t i = cands_.size(); i-- > 0;) removeCandidate(i);
  rescale_ = true;
  int last = from;
  std::vector<double> logPhi, scratch;
  size_t segmentFirstNode = bolt_.nodes.size();
  addCandidatesAround(from);
  while (!reached(bolt_.nodes[size_t(last)].cell, target)) {
    if (size_t(step_) >= p_.maxSteps)
      return overLimit("/maxSteps", "growth step budget of " + std::to_string(p_.maxSteps) + " cells exhausted");
    ++step_;
    expireCandidates();
    if (cands_.empty()) {
      reviveFrontier(from, segmentFirstNode);
      if (cands_.empty()) return unsatisfiable(field, "the bolt enclosed itself before reaching the target");
    }
    size_t pick = 0;
    if (p_.method == Method::kFast) {
      if (reference_) {  // only the error needs every log Phi: all of it is the error's time
        Stopwatch w;
        const double before = errorMs_;
        weighCandidates(logPhi);
        errorMs_ = before + w.ms();
      }
      pick = sampleFast();
    } else {
      weighCandidates(logPhi);
      pick = sample(logPhi, exponent_, rng_, scratch);
    }
    if (laplace_ && laplace_->exhausted())
      return overLimit("/grid", "the field at the bolt fell below 1e-" +
                                    std::to_string(5 * detail::DeepField::kMaxStages) +
                                    " of the target's, beyond what the exact solver resolves");
    Candidate chosen = cands_[pick];
    last = addNode(chosen.cell, chosen.parent);
    addCandidatesAround(last);
    followWaypoints(chosen.cell, waypoints, wp);
  }
  if (laplace_) {
    lastResidual_ = laplace_->residual();
    double& deepest = bolt_.stats.counters["deepestStage"];
    deepest = std::max(deepest, double(laplace_->deepestStage()));
    bolt_.stats.counters["stageSolves"] += laplace_->stageSolves();
  }
  ++step_;
  const Cell struck = toRegion_ ? regionCellTouching(bolt_.nodes[size_t(last)].cell) : target;
  reserved_.at(g_.index(struck)) = 0;
  addNode(struck, last);
  return std::nullopt;
}

std::optional<Error> Grower::run() {
  auto checkCell = [&](Cell c, const std::string& field) -> std::optional<Error> {
    if (!g_.inside(c.x, c.y, c.z)) return invalid(field, "is outside the grid");
    if (g_.blocked(c.x, c.y, c.z)) return unsatisfiable(field, "is inside an obstacle");
    return std::nullopt;
  };
  if (auto e = checkCell(p_.start, "/start")) return e;
  for (size_t k = 0; k < p_.targets.size(); ++k) {
    std::string f = "/targets/" + std::to_string(k);
    if (auto e = checkCell(p_.targets[k], f)) return e;
    Cell prev = k == 0 ? p_.start : p_.targets[k - 1];
    if (p_.targets[k] == prev) return unsatisfiable(f, k == 0 ? "equals start" : "equals the previous target");
    for (size_t j = 0; j < k; ++j)
      if (p_.targets[j] == p_.targets[k]) return unsatisfiable(f, "repeats an earlier target");
    if (p_.targets[k] == p_.start) return unsatisfiable(f, "equals start");
    if (!region_.empty() && region_[g_.index(p_.targets[k])]) return unsatisfiable(f, "lies in the target region");
  }
  if (!region_.empty()) {
    if (region_[g_.index(p_.start)]) return unsatisfiable("/start", "lies in the target region");
    if (std::find(region_.begin(), region_.end(), uint8_t(1)) == region_.end())
      return unsatisfiable("/targetRegion", "has no cell outside the obstacles");
  }
  if (p_.method == Method::kFast && p_.depth) {
    Stopwatch w;
    volumeMap_ = detail::cachedBoundary(p_.width, p_.height, p_.depth, p_.obstacles);
    bolt_.stats.counters["boundaryMapMs"] = w.ms();
    bolt_.stats.counters["boundaryMapCached"] = volumeMap_.cached ? 1 : 0;
  } else if (p_.method == Method::kFast) {
    Stopwatch w;
    boundaryMap_ = detail::cachedBoundary(p_.width, p_.height, p_.obstacles);
    bolt_.stats.counters["boundaryMapMs"] = w.ms();
    bolt_.stats.counters["boundaryMapCached"] = boundaryMap_.cached ? 1 : 0;
    boundaryMemo_ = detail::CellMap<float>(g_.cells());
  }
  addNode(p_.start, -1);
  for (size_t k = 0; k < p_.targets.size() + (region_.empty() ? 0 : 1); ++k) {
    if (auto e = growSegment(k)) return e;
    bolt_.mainChannel.clear();
  }
  for (int n = int(bolt_.nodes.size()) - 1; n >= 0; n = bolt_.nodes[size_t(n)].parent) bolt_.mainChannel.push_back(n);
  std::reverse(bolt_.mainChannel.begin(), bolt_.mainChannel.end());

  Stats& s = bolt_.stats;
  s.counters["steps"] = step_;
  s.counters["cells"] = double(bolt_.nodes.size());
  s.counters["candidatesMax"] = double(candidatesMax_);
  if (p_.method == Method::kCharges) s.counters["chargesEta"] = exponent_;
  if (p_.method == Method::kFast) {  // the setting that ran (calibrate() or the request's own)
    s.counters["axisGrowth"] = p_.axisGrowth;
    s.counters["lifetime"] = p_.lifetime;
    s.counters["screeningRadius"] = radius_;
  }
  if (p_.method == Method::kDbm) {
    s.counters["solverIterations"] = solverIterations_;
    s.counters["residual"] = lastResidual_;
    s.counters["directSteps"] = double(directSteps_);
    // The solver that ran: the capacitance method hands a bolt that outgrows it to MGPCG.
    const std::string iterative = toString(p_.solver == Solver::kCg ? Solver::kCg : Solver::kMgpcg);
    s.method = "dbm-" + (!directSteps_ ? iterative : !iterativeSteps_ ? "capacitance" : "capacitance+" + iterative);
  }
  if (p_.measureError && errorSteps_ > 0) {
    s.error = errorSum_ / errorSteps_;
    s.errorMetric = "mean per-step total-variation distance of the candidate distribution";
    s.reference = "dbm, converged Laplace solve (MGPCG, relative residual 1e-10)";
  }
  s.errorMs = errorMs_;
  return std::nullopt;
}

}  // namespace

Result<Bolt> grow(const Params& params) {
  if (auto e = validate(params)) return *e;
  if (size_t(params.width) * size_t(params.height) * size_t(std::max(params.depth, 1)) > (size_t(1) << 30))
    return overLimit("/grid", "grid too large");
  Stopwatch watch;
  Bolt bolt;
  bolt.depth = params.depth;
  Grower grower(params, bolt);
  if (auto e = grower.run()) return *e;
  if (bolt.stats.method.empty()) bolt.stats.method = toString(params.method);  // dbm's names its solver
  bolt.stats.elapsedMs = watch.ms() - bolt.stats.errorMs;                      // the method's own time
  return bolt;
}

}  // namespace effects::lightning
