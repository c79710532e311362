// The dielectric breakdown model (Niemeyer et al. 1984): every step solves the Laplace
// equation with the bolt, the obstacles and the outside at Phi = 0 and the target (or the
// whole region) at 1, and reads Phi at the candidates. The field (deep_field.h) follows the
// bolt as cells are fixed; which solver runs is solver_choice.h's rule.
#include <algorithm>
#include <atomic>
#include <cfloat>
#include <cmath>
#include <string>

#include "draw.h"
#include "growth.h"
#include "hooks.h"
#include "solver_choice.h"

namespace effects::lightning::detail {

std::unique_ptr<DeepField> dbmProblem(const Growth& s, Cell target, Solver solver) {
  const Params& p = s.p;
  size_t fixedCells = s.bolt.nodes.size() + 1;
  for (uint8_t o : p.obstacles) fixedCells += o != 0;
  if (s.toRegion)
    for (uint8_t r : s.region) fixedCells += r;
  std::unique_ptr<Potential> lap =
      potentialFor(p.width, p.height, p.depth, solver, fixedCells, fixedCells, p.parallel);  // room to grow
  auto field = std::make_unique<DeepField>(std::move(lap), p.width, p.height, p.depth, p.parallel);
  for (size_t i = 0; i < s.g.cells(); ++i)
    if (!p.obstacles.empty() && p.obstacles[i]) field->fix(s.g.cellAt(i), 0.0);
  for (const Node& n : s.bolt.nodes) field->fix(n.cell, 0.0);
  if (!s.toRegion) field->fix(target, 1.0);
  for (size_t i = 0; s.toRegion && i < s.region.size(); ++i)
    if (s.region[i]) field->fix(s.g.cellAt(i), 1.0);
  return field;
}

namespace {

std::atomic<bool> boundedDraw{true};

// The bounded draw (docs/effects.md section 1.3). Fixing a cell at 0 only lowers Phi (the
// discrete maximum principle), so within a segment the last Phi computed at a cell bounds
// every later one from above; the draw needs exact weights only where those bounds leave the
// pick open. The slack (relative to the last step's largest candidate Phi P, and absolute)
// covers the direct solver's rounding (at most 1e-9 of P and 5e-14 absolute, measured at
// 1024^2: docs/lightning-hero.md); kFirstWeight picks what is computed before the
// first try (bounds whose weight, relative to the largest potential's, is at least that).
constexpr double kBoundSlackRelative = 1e-7, kBoundSlackAbsolute = 1e-11;
constexpr double kFirstWeight = 1e-4;

class Dbm final : public PhiMethod {
 public:
  explicit Dbm(Growth& growth) : s_(growth), p_(growth.p) {}

  double exponent() const override { return p_.eta; }
  bool guided() const override { return false; }
  void startSegment(Cell target) override {
    field_ = dbmProblem(s_, target, p_.solver);
    top_ = 0;
    if (drawsItself()) bound_.assign(s_.g.cells(), -1.0);  // a new problem: nothing known
  }
  // The direct solver's steps draw from bounds in 2-D; measuring the error needs every
  // candidate's Phi, eta 0 weighs them alike whatever Phi is, and in 3-D, where the field is
  // less screened, the draw computed about 70 % of the candidates and took longer than
  // computing them all (docs/lightning-hero.md).
  bool drawsItself() const override {
    return boundedDraw && p_.solver == Solver::kCapacitance && p_.eta > 0 && !p_.measureError && p_.depth == 0;
  }
  size_t draw(Rng& rng) override;
  void cellAdded(Cell c) override {
    if (field_) field_->fix(c, 0.0);
  }
  void logPhi(std::vector<double>& out) override {
    probes_.resize(s_.cands.size());
    for (size_t i = 0; i < s_.cands.size(); ++i) probes_[i] = s_.cands[i].cell;
    solverIterations_ += field_->solve(p_.solver, p_.tolerance, probes_, logPhi_);
    (field_->direct() ? directSteps_ : iterativeSteps_) += 1;
    out = logPhi_;
  }
  std::optional<Error> fieldError() const override {
    if (!field_->exhausted()) return std::nullopt;
    return overLimit("/grid", "the field at the bolt fell below 1e-" + std::to_string(5 * DeepField::kMaxStages) +
                                  " of the target's, beyond what the exact solver resolves");
  }
  void endSegment() override {
    lastResidual_ = field_->residual();
    double& deepest = s_.bolt.stats.counters["deepestStage"];
    deepest = std::max(deepest, double(field_->deepestStage()));
    s_.bolt.stats.counters["stageSolves"] += field_->stageSolves();
  }
  void report(Stats& s) const override {
    s.counters["solverIterations"] = solverIterations_;
    s.counters["residual"] = lastResidual_;
    s.counters["directSteps"] = double(directSteps_);
    // The bounded draw's direct steps: the candidates they drew from, and at how many of those
    // they computed Phi (without it, at every one).
    if (drawsItself()) {
      s.counters["candidatesOffered"] = double(offered_);
      s.counters["candidatesWeighed"] = double(weighed_);
    }
    // The solver that ran: the capacitance method hands a bolt that outgrows it to MGPCG.
    const std::string iterative = toString(p_.solver == Solver::kCg ? Solver::kCg : Solver::kMgpcg);
    s.method = "dbm-" + (!directSteps_ ? iterative : !iterativeSteps_ ? "capacitance" : "capacitance+" + iterative);
  }

 private:
  Growth& s_;
  const Params& p_;
  std::unique_ptr<DeepField> field_;
  std::vector<Cell> probes_;     // the candidates' cells, for DeepField::solve
  std::vector<double> logPhi_;  // their log Phi from it
  double solverIterations_ = 0, lastResidual_ = 0;
  size_t directSteps_ = 0, iterativeSteps_ = 0;  // steps solved by each kind of solver
  // The bounded draw: per grid cell the last Phi computed there in this segment (-1: none),
  // the last step's largest candidate Phi, and the step's scratch (by slot).
  std::vector<double> bound_;
  double top_ = 0;
  size_t offered_ = 0, weighed_ = 0;
  std::vector<uint8_t> known_, ask_;
  std::vector<double> phi_, lo_, hi_, scratch_;
  std::vector<size_t> open_;
};

size_t Dbm::draw(Rng& rng) {
  const size_t n = s_.cands.size();
  probes_.resize(n);
  for (size_t i = 0; i < n; ++i) probes_[i] = s_.cands[i].cell;
  auto everyCandidate = [&] {  // the draw from every candidate's Phi, as without bounds
    logPhi(logPhi_);
    return sample(logPhi_, p_.eta, rng, scratch_);
  };
  if (!field_->solveDirect(p_.solver, p_.tolerance)) return everyCandidate();
  const double slack = kBoundSlackRelative * top_ + kBoundSlackAbsolute;
  known_.assign(n, 0);
  ask_.assign(n, 0);
  phi_.resize(n);
  // Computes the asked candidates, their Phi their bounds from now on; top: the largest known.
  double top = 0;
  auto compute = [&] {
    field_->phiDirect(probes_, ask_, phi_);
    for (size_t i = 0; i < n; ++i) {
      if (!ask_[i]) continue;
      ask_[i] = 0, known_[i] = 1, ++weighed_;
      bound_[s_.g.index(probes_[i])] = phi_[i];
      top = std::max(top, phi_[i]);
    }
  };
  auto upper = [&](size_t i) { return bound_[s_.g.index(probes_[i])] + slack; };
  // First every candidate without a bound and those whose bound weighs kFirstWeight of the
  // last step's largest; then any whose bound is above the largest found, until none is (the
  // largest is then exact, as solve() finds it).
  const double firstBound = top_ * std::pow(kFirstWeight, 1 / p_.eta);
  for (size_t i = 0; i < n; ++i) {
    const double b = bound_[s_.g.index(probes_[i])];
    ask_[i] = b < 0 || b + slack >= firstBound;
  }
  for (bool more = true; more;) {
    compute();
    more = false;
    for (size_t i = 0; i < n; ++i)
      if (!known_[i] && upper(i) >= top) ask_[i] = 1, more = true;
  }
  if (top < DeepField::kDeepen) return everyCandidate();  // the field needs solve()'s care
  field_->setLargest(top);
  top_ = top;
  ++directSteps_;
  offered_ += n;
  // Weights as candidateWeights makes them (relative to the largest), exact or bounded.
  const double logTop = logPotential(top);
  auto weight = [&](double phi) { return relativeWeight(logPotential(phi), p_.eta, logTop); };
  lo_.resize(n);
  hi_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    if (known_[i]) {
      lo_[i] = hi_[i] = weight(phi_[i]);
    } else {
      lo_[i] = 0;
      hi_[i] = weight(upper(i));
    }
  }
  const double u = rng.uniform();
  for (;;) {
    const size_t pick = decidedDraw(lo_, hi_, u);
    if (pick != kUndecided) return pick;
    // Open: compute the unknown candidates with the largest bounds, half their bounded weight.
    open_.clear();
    double openWeight = 0;
    for (size_t i = 0; i < n; ++i)
      if (!known_[i]) open_.push_back(i), openWeight += hi_[i];
    if (open_.empty()) break;
    std::sort(open_.begin(), open_.end(), [&](size_t a, size_t b) { return hi_[a] > hi_[b]; });
    double asked = 0;
    for (size_t k = 0; k < open_.size() && (asked < 0.5 * openWeight || k < 64); ++k)
      ask_[open_[k]] = 1, asked += hi_[open_[k]];
    compute();
    for (size_t i : open_)
      if (known_[i]) lo_[i] = hi_[i] = weight(phi_[i]);
  }
  // Every weight exact and the pick still within the margin: sampleAt's own sums decide it.
  logPhi_.resize(n);
  for (size_t i = 0; i < n; ++i) logPhi_[i] = logPotential(phi_[i]);
  return sampleAt(logPhi_, p_.eta, u, scratch_);
}

}  // namespace

std::unique_ptr<PhiMethod> dbmMethod(Growth& growth) { return std::make_unique<Dbm>(growth); }

}  // namespace effects::lightning::detail

namespace effects::lightning {

void setBoundedDraw(bool on) { detail::boundedDraw = on; }

}  // namespace effects::lightning
