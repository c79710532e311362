// Private to effects/lightning: DBM's potential kept relative to the bolt's candidates, for
// bolts whose field is far below the fixed values (docs/effects.md section 1.3, deep fields).
//
// Ahead of a bolt deep in a channel of width w the field decays like exp(-pi L / (w + 1)): at
// L = 64, w = 3 it is 1e-22, far below what a solve to a residual relative to the target's
// values resolves, and past L / (w + 1) ~ 225 it underflows double. The candidates' weights then
// become noise and the bolt fills its channel. Growth needs the candidates' potentials only up
// to a common factor, so DeepField solves in stages: where the largest candidate potential P of
// the current stage is below kDeepen, every cell whose potential is at least kCut (the target
// side) is frozen at its value divided by kCut, and the rest is solved again as a new stage
// with those values fixed (its values are the true ones times 1 / kCut per stage; their log
// scale is kept beside). A frozen cell's value is right while the bolt is far from it: the
// bolt's effect on a cell at potential kCut is of the order (P / kCut)^2 relative; when P rises
// above kPop the stage is dropped and the one below solved again with the bolt as it is now.
// Every solve stops at a residual of tolerance x P (relative to ||b||, at least kStageTolerance):
// the request's tolerance is the candidates' relative accuracy, not the target's.
// Nothing in this is about channels: deep pockets behind obstacles and 3-D tubes take the same
// path, and a bolt whose candidates stay above kDeepen (every open grid) never leaves stage 0.
#pragma once

#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "laplace.h"

namespace effects::lightning::detail {

class DeepField {
 public:
  // base: the solver of stage 0, nothing fixed yet (fix() fixes the obstacles, bolt and target
  // in it). It may be the direct capacitance solver, which a cut replaces by the iterative one.
  // One solver hierarchy lives at a time (a stage below is built again when the bolt comes
  // back to it); the stages add 11 bytes a cell.
  // parallel: for the stages it builds (potentialFor); null: this thread.
  DeepField(std::unique_ptr<Potential> base, int width, int height, int depth, Parallel* parallel = nullptr);
  ~DeepField();
  // Fixes a cell at a value in every stage: 0 (obstacles, bolt cells) or the target's 1.
  void fix(Cell c, double value);
  // Solves for this step, then deepens or drops stages until the largest potential at the
  // probes (the candidates) is resolved: at or above kDeepen in its stage and below kPop.
  // Sets logPhi to log Phi at each probe in the scale of stage 0 (the target at 1); a potential
  // that the final stage leaves at or below 0 (far below its resolution) counts as the smallest
  // normal double of that stage, so that eta near 0 still weighs it (Phi^eta -> 1). Returns the
  // solver iterations, every stage's included.
  int solve(Solver solver, double tolerance, const std::vector<Cell>& probes, std::vector<double>& logPhi);
  // A step of the direct solver without every probe (dbm.cpp's bounded draw). Where stage 0 is
  // on the direct solver, solveDirect solves it as solve() would and returns true; phiDirect
  // then gives Phi at the probes that `which` marks (the others' rows are kept as solve()
  // keeps them, so the solver's limits fall where they would), and the caller, having found
  // the largest potential at the probes to be at least kDeepen, hands it to setLargest, which
  // solve() would have found. False: nothing was solved, solve() this step.
  bool solveDirect(Solver solver, double tolerance);
  void phiDirect(const std::vector<Cell>& probes, const std::vector<uint8_t>& which, std::vector<double>& phi) {
    field_->phiAt(probes, phi, which.data());
  }
  void setLargest(double top) { estimate_ = top; }
  double residual() { return current().residual(); }
  bool direct() { return k_ == 0 && current().direct(); }
  // The deepest stage reached so far (0: never cut).
  int deepestStage() const { return deepest_; }
  // Stages made or remade (each a solve from scratch).
  int stageSolves() const { return stageSolves_; }
  // Whether the stages ran out (kMaxStages): the field is below about 1e-(5 * 65535) of the
  // target's, and the potentials the candidates get are not resolved. (Where no field reaches
  // the candidates at all, they are weighed alike instead, as DBM with no field does.)
  bool exhausted() const { return exhausted_; }

  static constexpr double kDeepen = 1e-8;            // P below this: cut a new stage
  static constexpr double kCut = 1e-5;               // cells at or above this freeze
  static constexpr double kPop = 1e-2;               // P above this: the stage is dropped
  static constexpr double kStageTolerance = 1e-12;   // relative residual of a cut's solve
  static constexpr int kMaxStages = 65535;

 private:
  Potential& current();  // the current stage's solver, built if a pop dropped it
  size_t index(Cell c) const { return (size_t(c.z) * size_t(h_) + size_t(c.y)) * size_t(w_) + size_t(c.x); }
  Cell cellAt(size_t i) const;
  std::unique_ptr<Potential> build(int stage) const;  // from scratch: zero cells, the stage's cut (stage 0: the targets)
  bool deepen();  // cuts a stage; false where none was (nothing to cut, or kMaxStages)
  // Whether a path of cells not fixed at 0 (4 or 6 neighbours, the Laplacian's) joins a probe
  // to a target: where none does, the field there is exactly 0.
  bool reachable(const std::vector<Cell>& probes) const;
  void pop();
  // The largest potential at the probes in the current stage (phi_ keeps them all).
  double largest(const std::vector<Cell>& probes, bool& inRegion);

  int w_, h_, d_;
  size_t cells_;
  Parallel* parallel_;
  std::unique_ptr<Potential> field_;  // the current stage's solver (null: build it when needed)
  int k_ = 0, deepest_ = 0, stageSolves_ = 0;
  double estimate_ = 1;             // the candidates' largest potential at the last solve (its stage)
  bool exhausted_ = false;
  std::vector<uint8_t> zero_;       // cells fixed at 0 (outside the problem: obstacles, bolt)
  std::vector<std::pair<Cell, double>> targets_;  // cells stage 0 fixes at a non-zero value
  std::vector<uint16_t> cutStage_;  // the stage a cell froze at (0: never); made at the first cut
  std::vector<double> cutValue_;    // its value there, in that stage's scale
  std::vector<double> phi_;         // the probes' potentials in the current stage
};

}  // namespace effects::lightning::detail
