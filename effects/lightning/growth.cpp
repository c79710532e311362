// Laplacian growth's loop, the Grower: the bolt and its candidates (the free cells next to
// it), the A* guide and its waypoints, chain targets and a target region, sampling, and the
// per-step error against the converged Laplace solution. How the candidates are weighed is
// the method's (growth.h's PhiMethod: fast.cpp, dbm.cpp, charges.cpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "astar.h"
#include "draw.h"
#include "growth.h"

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

using detail::Candidate;
using detail::candidateWeights;
using detail::sample;

std::unique_ptr<detail::PhiMethod> methodFor(detail::Growth& growth, int radius) {
  switch (growth.p.method) {
    case Method::kDbm: return detail::dbmMethod(growth);
    case Method::kCharges: return detail::chargesMethod(growth);
    case Method::kFast: break;
  }
  return detail::fastMethod(growth, radius);
}

class Grower {
 public:
  Grower(const Params& p, Bolt& bolt)
      : p_(p), s_(p, bolt), stencil_(detail::stencil(p.neighbourhood)) {
    const size_t cells = s_.g.cells();
    nodeOf_ = detail::CellIndex(cells);
    candidateOf_ = detail::CellIndex(cells);
    reserved_ = detail::CellMap<uint8_t>(cells);
    if (radius_ > 1) near_ = detail::CellMap<uint8_t>(cells);
    for (const Cell& t : p.targets)
      if (s_.g.inside(t.x, t.y, t.z)) reserved_.at(s_.g.index(t)) = 1;
    if (!p.targetRegion.empty()) {  // the region less the obstacles, reserved like targets
      s_.region.assign(cells, 0);
      for (size_t i = 0; i < cells; ++i)
        if (p.targetRegion[i] && (p.obstacles.empty() || !p.obstacles[i])) s_.region[i] = reserved_.at(i) = 1;
    }
  }

  std::optional<Error> run();

 private:
  // Free for growth: inside, no obstacle, not bolt, not a target still to be reached (those
  // join the bolt only when it touches them).
  bool free(int x, int y, int z) const {
    if (!s_.g.inside(x, y, z) || s_.g.blocked(x, y, z)) return false;
    size_t i = s_.g.index(x, y, z);
    return nodeOf_.get(i) < 0 && !reserved_.get(i);
  }
  int addNode(Cell c, int parent);
  void addCandidatesAround(int node);
  void removeCandidate(size_t slot);
  void dropOlderThan(int age);
  void screenAround(Cell c);
  std::optional<Error> growSegment(size_t k);
  std::vector<Cell> guidePath(size_t k, Cell fromCell, Cell target);
  bool inRegion(int x, int y, int z) const { return s_.g.inside(x, y, z) && s_.region[s_.g.index(x, y, z)]; }
  // The segment's end is in reach of c: its target touches c, or (toRegion) a region cell does.
  bool reached(Cell c, Cell target) const;
  Cell regionCellTouching(Cell c) const;
  void reviveFrontier(int from, size_t segmentFirstNode);
  size_t pick(std::vector<double>& logPhi, std::vector<double>& scratch);
  // Params::progress, at most every kProgressIntervalMs: after cell c joined segment k of
  // `segments`, aimed at `aim` from `from`. False when the callback asks to stop.
  bool reportProgress(size_t k, Cell c, Cell from, Cell aim);
  void weighCandidates(std::vector<double>& logPhi);
  void followWaypoints(Cell newest, const std::vector<Cell>& waypoints, size_t& wp);
  double stepError(const std::vector<double>& logPhi);

  bool touching(Cell a, Cell b) const { return detail::touching(a, b, p_.neighbourhood); }

  const Params& p_;
  detail::Growth s_;
  Stopwatch sinceProgress_;      // since the last progress report (or the start)
  double nearestToAim_ = -1;     // the segment's bolt cell nearest its aim: the distance (-1: none yet)
  detail::Stencil stencil_;
  // N counted within radius_ (1: the adjacent cells); the fast method's alone but for 1.
  const int radius_ = screeningRadius(p_);
  std::unique_ptr<detail::PhiMethod> method_ = methodFor(s_, radius_);
  detail::CellIndex nodeOf_, candidateOf_;
  detail::CellMap<uint8_t> reserved_;
  detail::CellMap<uint8_t> near_;  // radius_ > 1: bolt cells within radius_ of each cell (<= 15^2)
  std::unique_ptr<detail::DeepField> reference_;  // measureError: the converged field
  std::vector<Cell> probes_;                      // the reference's cells, for DeepField::solve
  Rng rng_{p_.seed};
  int step_ = 0;
  double errorSum_ = 0;
  int errorSteps_ = 0;
  double errorMs_ = 0;  // the reference's solves: not the method's time
  size_t candidatesMax_ = 0;
};

// A new bolt cell screens every cell within radius_: their counts rise, candidates among them
// are weighed again.
void Grower::screenAround(Cell c) {
  for (int y = std::max(0, c.y - radius_); y <= std::min(p_.height - 1, c.y + radius_); ++y)
    for (int x = std::max(0, c.x - radius_); x <= std::min(p_.width - 1, c.x + radius_); ++x) {
      const size_t i = s_.g.index(x, y, 0);
      ++near_.at(i);
      if (const int32_t slot = candidateOf_.get(i); slot >= 0) {
        Candidate& cand = s_.cands[size_t(slot)];
        cand.neighbours = near_.get(i);
        method_->neighboursChanged(cand);
        method_->slotChanged(size_t(slot));
      }
    }
}

int Grower::addNode(Cell c, int parent) {
  Bolt& bolt = s_.bolt;
  int id = int(bolt.nodes.size());
  bolt.nodes.push_back({c, parent, step_});
  nodeOf_.set(s_.g.index(c), id);
  if (int slot = candidateOf_.get(s_.g.index(c)); slot >= 0) removeCandidate(size_t(slot));
  if (radius_ > 1) screenAround(c);
  if (reference_) reference_->fix(c, 0.0);
  method_->cellAdded(c);
  return id;
}

void Grower::removeCandidate(size_t slot) {
  std::vector<Candidate>& cands = s_.cands;
  candidateOf_.set(s_.g.index(cands[slot].cell), -1);
  if (slot + 1 != cands.size()) {
    cands[slot] = cands.back();
    candidateOf_.set(s_.g.index(cands[slot].cell), int32_t(slot));
  }
  method_->slotChanged(slot);
  method_->slotChanged(cands.size() - 1);
  cands.pop_back();
}

void Grower::addCandidatesAround(int node) {
  std::vector<Candidate>& cands = s_.cands;
  Cell c = s_.bolt.nodes[size_t(node)].cell;
  for (int k = 0; k < stencil_.size; ++k) {
    int x = c.x + stencil_.dx[k], y = c.y + stencil_.dy[k], z = c.z + stencil_.dz[k];
    if (!free(x, y, z)) continue;
    size_t i = s_.g.index(x, y, z);
    if (const int32_t slot = candidateOf_.get(i); slot >= 0) {
      Candidate& cand = cands[size_t(slot)];
      cand.born = step_;
      cand.parent = node;
      if (radius_ == 1) {  // with a wider radius, screenAround() has counted and weighed it
        cand.neighbours = std::min(cand.neighbours + 1, stencil_.size);
        method_->neighboursChanged(cand);
      }
      method_->slotChanged(size_t(slot));
      continue;
    }
    Candidate cand{{x, y, z}, step_, radius_ > 1 ? int(near_.get(i)) : 0, node, 0.0};
    if (radius_ == 1)
      for (int j = 0; j < stencil_.size; ++j) {
        int nx = x + stencil_.dx[j], ny = y + stencil_.dy[j], nz = z + stencil_.dz[j];
        if (s_.g.inside(nx, ny, nz) && nodeOf_.get(s_.g.index(nx, ny, nz)) >= 0) ++cand.neighbours;
      }
    method_->candidateAdded(cand);
    candidateOf_.set(i, int32_t(cands.size()));
    cands.push_back(cand);
    method_->slotChanged(cands.size() - 1);
  }
  candidatesMax_ = std::max(candidatesMax_, cands.size());
}

// Seed 002's lifetime: candidates that gained no bolt neighbour for more than `age` steps go.
void Grower::dropOlderThan(int age) {
  for (size_t i = s_.cands.size(); i-- > 0;)
    if (step_ - s_.cands[i].born > age) removeCandidate(i);
}

double Grower::stepError(const std::vector<double>& logPhi) {
  // Total-variation distance between this method's candidate distribution and the one the
  // converged Laplace solution gives on the same bolt state (over all free bolt neighbours).
  const std::vector<Candidate>& cands = s_.cands;
  std::vector<double> p;
  const double pSum = candidateWeights(logPhi, method_->exponent(), p);
  for (double& v : p) v /= pSum;
  // Reference support: every free cell next to a bolt cell.
  std::vector<size_t> cells;
  for (const Node& n : s_.bolt.nodes)
    for (int k = 0; k < stencil_.size; ++k) {
      int x = n.cell.x + stencil_.dx[k], y = n.cell.y + stencil_.dy[k], z = n.cell.z + stencil_.dz[k];
      if (free(x, y, z)) cells.push_back(s_.g.index(x, y, z));
    }
  std::sort(cells.begin(), cells.end());
  cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
  probes_.resize(cells.size());
  for (size_t k = 0; k < cells.size(); ++k) probes_[k] = s_.g.cellAt(cells[k]);
  std::vector<double> refLogPhi, refPhi;
  reference_->solve(Solver::kMgpcg, 1e-10, probes_, refLogPhi);
  const double refSum = candidateWeights(refLogPhi, p_.eta, refPhi);  // the weights
  double tv = 0;
  std::vector<double> mine(cells.size(), 0.0);
  double outside = 0;  // probability this method puts outside the reference support (none in practice)
  for (size_t i = 0; i < cands.size(); ++i) {
    auto it2 = std::lower_bound(cells.begin(), cells.end(), s_.g.index(cands[i].cell));
    if (it2 != cells.end() && *it2 == s_.g.index(cands[i].cell))
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
  const bool copy = k > 0 || (!s_.region.empty() && !s_.toRegion);
  std::vector<uint8_t> withBolt;
  if (copy) {
    withBolt = p_.obstacles;
    if (withBolt.empty()) withBolt.assign(s_.g.cells(), 0);
    for (const Node& n : s_.bolt.nodes) withBolt[s_.g.index(n.cell)] = 1;
    if (!s_.toRegion)
      for (size_t i = 0; i < s_.region.size(); ++i) withBolt[i] |= s_.region[i];
    withBolt[s_.g.index(fromCell)] = 0;
  }
  const std::vector<uint8_t>& blocked = copy ? withBolt : p_.obstacles;
  Stopwatch guideWatch;
  std::vector<Cell> path =
      s_.toRegion ? astarToRegion(p_.width, p_.height, blocked, fromCell, s_.region, p_.neighbourhood, p_.depth)
                  : astar(p_.width, p_.height, blocked, fromCell, target, p_.neighbourhood, p_.depth);
  s_.bolt.stats.counters["guideMs"] += guideWatch.ms();
  return path;
}

bool Grower::reached(Cell c, Cell target) const {
  if (!s_.toRegion) return touching(c, target);
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

// Every candidate expired or the sub-bolt is boxed in: the candidates around the segment's
// start and every node it added come back.
void Grower::reviveFrontier(int from, size_t segmentFirstNode) {
  s_.bolt.stats.counters["revivals"] += 1;
  addCandidatesAround(from);
  for (size_t n = segmentFirstNode; n < s_.bolt.nodes.size(); ++n) addCandidatesAround(int(n));
}

// log Phi of every candidate for this step (DBM solves here), and its error against the
// converged solution when measured.
void Grower::weighCandidates(std::vector<double>& logPhi) {
  method_->logPhi(logPhi);
  if (reference_) {
    Stopwatch w;
    errorSum_ += stepError(logPhi);
    ++errorSteps_;
    errorMs_ += w.ms();
  }
}

// The step's candidate, by Phi^eta. A method that keeps its own weights draws from them, and
// weighs every candidate only for the error (all of it the error's time).
size_t Grower::pick(std::vector<double>& logPhi, std::vector<double>& scratch) {
  if (!method_->drawsItself()) {
    weighCandidates(logPhi);
    return sample(logPhi, method_->exponent(), rng_, scratch);
  }
  if (reference_) {
    Stopwatch w;
    const double before = errorMs_;
    weighCandidates(logPhi);
    errorMs_ = before + w.ms();
  }
  return method_->draw(rng_);
}

// Seed 002 section 3.2: move on to the next waypoint early when the newest bolt cell is next
// to the current one or sees the next one.
void Grower::followWaypoints(Cell newest, const std::vector<Cell>& waypoints, size_t& wp) {
  while (wp + 1 < waypoints.size() &&
         (touching(newest, waypoints[wp]) || detail::lineOfSight(s_.g, newest, waypoints[wp + 1]))) {
    s_.anchor = newest;
    s_.attractor = waypoints[++wp];
    s_.towardsRegion = s_.toRegion && wp + 1 == waypoints.size();
    if (const int age = method_->legLifetime()) dropOlderThan(age);
    method_->newLeg();
  }
}

bool Grower::reportProgress(size_t k, Cell c, Cell from, Cell aim) {
  auto distance = [&](Cell a) {
    return std::sqrt(double(a.x - aim.x) * (a.x - aim.x) + double(a.y - aim.y) * (a.y - aim.y) +
                     double(a.z - aim.z) * (a.z - aim.z));
  };
  const double d = distance(c);
  if (nearestToAim_ < 0 || d < nearestToAim_) nearestToAim_ = d;
  if (sinceProgress_.ms() < kProgressIntervalMs) return true;
  sinceProgress_ = Stopwatch();
  const size_t segments = p_.targets.size() + (s_.region.empty() ? 0 : 1);
  const double span = distance(from);
  const double done = span > 0 ? std::clamp(1.0 - nearestToAim_ / span, 0.0, 1.0) : 1.0;
  Progress progress;
  progress.cells = s_.bolt.nodes.size();
  progress.steps = size_t(step_);
  progress.fraction = std::min(1.0, (double(k) + done) / double(segments));
  return p_.progress(progress);
}

std::optional<Error> Grower::growSegment(size_t k) {
  Bolt& bolt = s_.bolt;
  s_.toRegion = k == p_.targets.size();  // the last segment, when a region is given
  const Cell target = s_.toRegion ? Cell{} : p_.targets[k];
  const int from = k == 0 ? 0 : int(bolt.nodes.size()) - 1;  // previous target's node
  const std::string field = s_.toRegion ? "/targetRegion" : "/targets/" + std::to_string(k);
  const Cell fromCell = bolt.nodes[size_t(from)].cell;

  // Reachability (and the guide) with the bolt so far blocked, except the segment's start.
  std::vector<Cell> path = guidePath(k, fromCell, target);
  if (path.empty())
    return unsatisfiable(
        field, std::string(s_.toRegion ? "no cell of the region is reachable" : "target is unreachable") + " from " +
                   (k ? "the previous target" : "start"));
  const bool useGuide =
      method_->guided() && (p_.guide == Guide::kAstar || (p_.guide == Guide::kAuto && !p_.obstacles.empty()));
  // Towards a region, the axis (and fast's eqn 8) aims at the region's cell the search reached.
  std::vector<Cell> waypoints = useGuide ? detail::turningPoints(path) : std::vector<Cell>{path.back()};
  if (useGuide) bolt.guide.insert(bolt.guide.end(), waypoints.begin(), waypoints.end());
  size_t wp = 0;
  s_.anchor = fromCell;
  s_.attractor = waypoints[0];
  s_.towardsRegion = s_.toRegion && waypoints.size() == 1;
  method_->startSegment(target);
  if (p_.measureError) {
    Stopwatch w;
    reference_ = detail::dbmProblem(s_, target, Solver::kMgpcg);
    errorMs_ += w.ms();
  }

  nearestToAim_ = -1;
  // Chain lightning: the new segment grows from the previous target only.
  for (size_t i = s_.cands.size(); i-- > 0;) removeCandidate(i);
  int last = from;
  std::vector<double> logPhi, scratch;
  size_t segmentFirstNode = bolt.nodes.size();
  addCandidatesAround(from);
  while (!reached(bolt.nodes[size_t(last)].cell, target)) {
    if (size_t(step_) >= p_.maxSteps)
      return overLimit("/maxSteps", "growth step budget of " + std::to_string(p_.maxSteps) + " cells exhausted");
    ++step_;
    if (const int age = method_->lifetime()) dropOlderThan(age);
    if (s_.cands.empty()) {
      reviveFrontier(from, segmentFirstNode);
      if (s_.cands.empty()) return unsatisfiable(field, "the bolt enclosed itself before reaching the target");
    }
    const size_t chosen = pick(logPhi, scratch);
    if (auto e = method_->fieldError()) return e;
    const Candidate cand = s_.cands[chosen];
    last = addNode(cand.cell, cand.parent);
    addCandidatesAround(last);
    followWaypoints(cand.cell, waypoints, wp);
    if (p_.progress && !reportProgress(k, cand.cell, fromCell, path.back()))
      return Error{ErrorKind::kCancelled, "", "cancelled while growing, after " + std::to_string(step_) + " steps"};
  }
  method_->endSegment();
  ++step_;
  const Cell struck = s_.toRegion ? regionCellTouching(bolt.nodes[size_t(last)].cell) : target;
  reserved_.at(s_.g.index(struck)) = 0;
  addNode(struck, last);
  return std::nullopt;
}

std::optional<Error> Grower::run() {
  const detail::Grid& g = s_.g;
  const std::vector<uint8_t>& region = s_.region;
  auto checkCell = [&](Cell c, const std::string& field) -> std::optional<Error> {
    if (!g.inside(c.x, c.y, c.z)) return invalid(field, "is outside the grid");
    if (g.blocked(c.x, c.y, c.z)) return unsatisfiable(field, "is inside an obstacle");
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
    if (!region.empty() && region[g.index(p_.targets[k])]) return unsatisfiable(f, "lies in the target region");
  }
  if (!region.empty()) {
    if (region[g.index(p_.start)]) return unsatisfiable("/start", "lies in the target region");
    if (std::find(region.begin(), region.end(), uint8_t(1)) == region.end())
      return unsatisfiable("/targetRegion", "has no cell outside the obstacles");
  }
  method_->startRun();
  Bolt& bolt = s_.bolt;
  addNode(p_.start, -1);
  for (size_t k = 0; k < p_.targets.size() + (region.empty() ? 0 : 1); ++k) {
    if (auto e = growSegment(k)) return e;
    bolt.mainChannel.clear();
  }
  for (int n = int(bolt.nodes.size()) - 1; n >= 0; n = bolt.nodes[size_t(n)].parent) bolt.mainChannel.push_back(n);
  std::reverse(bolt.mainChannel.begin(), bolt.mainChannel.end());

  Stats& s = bolt.stats;
  s.counters["steps"] = step_;
  s.counters["cells"] = double(bolt.nodes.size());
  s.counters["candidatesMax"] = double(candidatesMax_);
  method_->report(s);
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
