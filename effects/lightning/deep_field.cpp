#include "deep_field.h"

#include <algorithm>
#include <cfloat>
#include <cmath>

#include "draw.h"
#include "solver_choice.h"

namespace effects::lightning::detail {

DeepField::DeepField(std::unique_ptr<Potential> base, int width, int height, int depth, Parallel* parallel)
    : w_(width), h_(height), d_(depth), cells_(size_t(width) * size_t(height) * size_t(std::max(depth, 1))),
      parallel_(parallel), field_(std::move(base)), zero_(cells_, 0) {}

DeepField::~DeepField() = default;

Cell DeepField::cellAt(size_t i) const {
  const size_t w = size_t(w_), h = size_t(h_);
  return Cell{int(i % w), int(i / w % h), int(i / (w * h))};
}

void DeepField::fix(Cell c, double value) {
  const size_t i = index(c);
  // A target the bolt reached (fixed at 0 now) is no longer a source.
  targets_.erase(std::remove_if(targets_.begin(), targets_.end(), [&](const auto& t) { return t.first == c; }),
                 targets_.end());
  if (value == 0.0)
    zero_[i] = 1;
  else
    targets_.emplace_back(c, value);
  // A cell fixed inside the frozen region (the bolt reached it, which kPop should have
  // prevented, or a new target) drops the stages down to one where it is an unknown; that
  // stage is built when next solved, with the cell in it.
  while (k_ > 0 && (value != 0.0 || (cutStage_[i] != 0 && cutStage_[i] <= k_))) pop();
  if (field_) field_->fix(c, value);
}

std::unique_ptr<Potential> DeepField::build(int stage) const {
  // A rebuilt stage is solved iteratively (solver_choice.h's rule for any solver but capacitance).
  std::unique_ptr<Potential> lap = potentialFor(w_, h_, d_, Solver::kMgpcg, 0, 0, parallel_);
  for (size_t i = 0; i < cells_; ++i) {
    if (zero_[i]) {
      lap->fix(cellAt(i), 0.0);
    } else if (stage > 0 && cutStage_[i] != 0 && cutStage_[i] <= stage) {
      // Cells frozen at earlier stages lie deep inside the region (a neighbour of an unknown is
      // within a factor 2 d of it, d the dimension); only the newest cut's values reach the
      // unknowns.
      lap->fix(cellAt(i), cutStage_[i] == stage ? cutValue_[i] : 0.0);
    }
  }
  if (stage == 0)
    for (const auto& [c, v] : targets_) lap->fix(c, v);
  return lap;
}

bool DeepField::reachable(const std::vector<Cell>& probes) const {
  std::vector<uint8_t> seen(cells_, 0);
  std::vector<size_t> queue;
  for (const auto& [c, v] : targets_) {
    seen[index(c)] = 1;
    queue.push_back(index(c));
  }
  const size_t w = size_t(w_), plane = w * size_t(h_);
  for (size_t head = 0; head < queue.size(); ++head) {
    const size_t i = queue[head];
    const Cell c = cellAt(i);
    auto visit = [&](bool inside, size_t j) {
      if (inside && !seen[j] && !zero_[j]) seen[j] = 1, queue.push_back(j);
    };
    visit(c.x > 0, i - 1);
    visit(c.x + 1 < w_, i + 1);
    visit(c.y > 0, i - w);
    visit(c.y + 1 < h_, i + w);
    if (d_) {
      visit(c.z > 0, i - plane);
      visit(c.z + 1 < d_, i + plane);
    }
  }
  for (const Cell& c : probes)
    if (seen[index(c)]) return true;
  return false;
}

Potential& DeepField::current() {
  if (!field_) {  // dropped by a pop: this stage anew, from the cells fixed so far
    field_ = build(k_);
    ++stageSolves_;
  }
  return *field_;
}

double DeepField::largest(const std::vector<Cell>& probes, bool& inRegion) {
  double top = 0;
  inRegion = false;
  current().phiAt(probes, phi_);
  for (size_t i = 0; i < probes.size(); ++i) {
    if (k_ > 0) {
      const uint16_t s = cutStage_[index(probes[i])];
      if (s != 0 && s <= k_) inRegion = true;
    }
    top = std::max(top, phi_[i]);
  }
  return top;
}

bool DeepField::deepen() {
  if (k_ == kMaxStages) {
    exhausted_ = true;
    return false;
  }
  if (cutStage_.empty()) {
    cutStage_.assign(cells_, 0);
    cutValue_.assign(cells_, 0.0);
  }
  const Potential& cur = current();
  const uint16_t next = uint16_t(k_ + 1);
  size_t cut = 0;
  for (size_t i = 0; i < cells_; ++i) {
    if (zero_[i] || cutStage_[i]) continue;
    const double v = cur.phi(cellAt(i));  // the fixed value on fixed cells (the target)
    if (v >= kCut) {
      cutStage_[i] = next;
      cutValue_[i] = v / kCut;
      ++cut;
    }
  }
  if (cut == 0) return false;  // no field left to cut at
  k_ = next;
  deepest_ = std::max(deepest_, k_);
  // One solver hierarchy at a time: the stage below is built again when the bolt comes back.
  field_.reset();
  current();
  return true;
}

void DeepField::pop() {
  for (size_t i = 0; i < cells_; ++i)
    if (cutStage_[i] == k_) cutStage_[i] = 0;
  --k_;
  field_.reset();     // built when next solved (a fix() may pop several stages first)
  estimate_ *= kCut;  // the candidates' potential in the scale of the stage below
}

bool DeepField::solveDirect(Solver solver, double tolerance) {
  if (k_ != 0 || !field_ || !field_->direct()) return false;
  field_->solve(solver, std::max(kStageTolerance, tolerance * estimate_));
  return true;
}

int DeepField::solve(Solver solver, double tolerance, const std::vector<Cell>& probes, std::vector<double>& logPhi) {
  // The residual goal (relative to ||b||) is the tolerance times the candidates' largest
  // potential, so that their potentials come out right to about `tolerance` relative wherever
  // the field is: the last step's largest to start with, then this step's if it fell.
  int it = 0;
  double goal = 0;
  auto run = [&](double g) {
    goal = g;
    it += current().solve(k_ ? Solver::kMgpcg : solver, g);
  };
  run(std::max(kStageTolerance, tolerance * estimate_));
  double top = 0;
  bool checkedReach = false;
  for (int pass = 0; pass < 4 * kMaxStages; ++pass) {  // each pass moves a stage or the goal
    bool inRegion = false;
    top = largest(probes, inRegion);
    if (k_ > 0 && (inRegion || top > kPop)) {
      pop();
      run(std::max(kStageTolerance, tolerance * top * kCut));
      continue;
    }
    // No field reaches the candidates where no path of unknown cells joins them to a target (a
    // bolt sealed off by a diagonal wall that the 5-point Laplacian sees as closed): they are
    // weighed alike, as with no field at all, and what a solve shows there is rounding. A
    // potential of 0 elsewhere is one that underflowed.
    if (top < kDeepen && !exhausted_) {
      if (!checkedReach) {
        checkedReach = true;
        if (!reachable(probes)) {
          std::fill(phi_.begin(), phi_.end(), 0.0);
          break;
        }
      }
      if (k_ == 0 && field_->direct()) {
        // The capacitance solver's sums cancel at these potentials, and a cut reads every
        // cell: stage 0 goes over to the iterative solver.
        field_.reset();
        run(kStageTolerance);
        continue;
      }
      if (goal > kStageTolerance) {  // a cut needs the values near kCut right
        run(kStageTolerance);
        continue;
      }
      if (!deepen()) {
        if (!exhausted_) std::fill(phi_.begin(), phi_.end(), 0.0);  // nothing to cut: no field
        break;
      }
      run(kStageTolerance);
      continue;
    }
    if (!current().direct() && goal > kStageTolerance && goal > 2 * tolerance * top) {
      run(std::max(kStageTolerance, tolerance * top));
      continue;
    }
    break;
  }
  estimate_ = top > 0 ? top : 1.0;
  logPhi.resize(probes.size());
  const double scale = k_ * std::log(kCut);
  for (size_t i = 0; i < probes.size(); ++i) logPhi[i] = logPotential(phi_[i]) + scale;
  return it;
}

}  // namespace effects::lightning::detail
