// The dielectric breakdown model (Niemeyer et al. 1984): every step solves the Laplace
// equation with the bolt, the obstacles and the outside at Phi = 0 and the target (or the
// whole region) at 1, and reads Phi at the candidates. The field (deep_field.h) follows the
// bolt as cells are fixed; which solver runs is solver_choice.h's rule.
#include <algorithm>
#include <string>

#include "growth.h"
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

class Dbm final : public PhiMethod {
 public:
  explicit Dbm(Growth& growth) : s_(growth), p_(growth.p) {}

  double exponent() const override { return p_.eta; }
  bool guided() const override { return false; }
  void startSegment(Cell target) override { field_ = dbmProblem(s_, target, p_.solver); }
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
};

}  // namespace

std::unique_ptr<PhiMethod> dbmMethod(Growth& growth) { return std::make_unique<Dbm>(growth); }

}  // namespace effects::lightning::detail
