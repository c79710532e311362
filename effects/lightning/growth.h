// Private to effects/lightning: what the Grower (growth.cpp: the loop of Laplacian growth)
// shares with the three ways of getting Phi, each behind PhiMethod in its own file:
//   fast.cpp     seed 002's eqns 4-8 (kFast), weights kept per candidate in a sum tree;
//   dbm.cpp      a converged Laplace solve every step (kDbm);
//   charges.cpp  Kim et al. 2007's incremental point charges (kCharges).
// The Grower owns the bolt, the candidates (cells next to the bolt), the guide and the
// per-step error; a method owns how the candidates are weighed and hears of every change to
// them through the hooks below, in the order the loop makes them.
#pragma once

#include <algorithm>
#include <memory>
#include <optional>
#include <vector>

#include "deep_field.h"
#include "grid.h"

namespace effects::lightning::detail {

struct Candidate {
  Cell cell;
  int born;        // step at which it last gained a bolt neighbour
  int neighbours;  // N of seed 002 eqn 6: adjacent bolt cells, 1..8 (1..4 in a 4-neighbourhood, 1..26 in
                   // 3-D); with a screening radius r > 1, the bolt cells within r (1..(2r+1)^2)
  int parent;      // node it attaches to if chosen: its newest bolt neighbour
  double charge;   // kCharges: sum over bolt cells of 1/r
  // kFast: log(2^G / (B * P)), fixed while the segment's axis stands, and Phi^eta relative
  // to the method's weight reference (kept per candidate: only cells that gain a neighbour
  // change, so a step costs one pass of additions, not a logarithm and a power per candidate).
  double logStatic = 0, weight = 0;
  double logBoundary = 0;  // kFast: log B, which no new axis changes
};

// The growth state a method reads: written by the Grower only.
struct Growth {
  Growth(const Params& params, Bolt& grown)
      : p(params), g{p.width, p.height, &p.obstacles, std::max(p.depth, 1)}, bolt(grown) {}

  const Params& p;
  Grid g;
  Bolt& bolt;
  std::vector<Candidate> cands;   // in slots; a removed slot takes the last candidate
  std::vector<uint8_t> region;    // Params::targetRegion less the obstacles (empty: none)
  bool toRegion = false;          // the segment grows to the region
  bool towardsRegion = false;     // ... and its axis ends on it (P = distance to the region)
  Cell anchor, attractor;         // the current axis: anchor -> attractor (seed 002 eqn 8's G)
};

// How one method weighs the candidates. Hooks default to nothing; the Grower calls them
// in this order each step: expiry (lifetime), logPhi and/or draw, then cellAdded and the
// candidate hooks for the chosen cell's neighbourhood.
class PhiMethod {
 public:
  virtual ~PhiMethod() = default;
  // The power the candidates' Phi is raised to (seed 002 eqn 2's eta).
  virtual double exponent() const = 0;
  // The method follows the A* guide's turning points (every method but DBM, whose Laplace
  // solutions have no local minima).
  virtual bool guided() const { return true; }
  // Steps a candidate lives without gaining a bolt neighbour (0: for ever), and, on a new leg
  // of the guide, the age past which candidates are dropped (0: none are).
  virtual int lifetime() const { return 0; }
  virtual int legLifetime() const { return 0; }
  // Before the first cell, and as a segment starts towards `target` (the region when
  // growth.toRegion), before its candidates are cleared.
  virtual void startRun() {}
  virtual void startSegment(Cell /*target*/) {}
  // A new leg of the guide: the axis (anchor, attractor) changed.
  virtual void newLeg() {}
  // A cell joined the bolt.
  virtual void cellAdded(Cell /*c*/) {}
  // A new candidate, before it takes its slot; a candidate whose count N changed; a slot whose
  // candidate changed, moved or left.
  virtual void candidateAdded(Candidate& /*c*/) {}
  virtual void neighboursChanged(Candidate& /*c*/) {}
  virtual void slotChanged(size_t /*slot*/) {}
  // The method keeps its own weights and draws from them without logPhi (the fast method):
  // logPhi then runs only to measure the error.
  virtual bool drawsItself() const { return false; }
  virtual size_t draw(Rng& /*rng*/) { return 0; }
  // log Phi of every candidate in slot order (-inf where Phi = 0). DBM solves its field here.
  virtual void logPhi(std::vector<double>& out) = 0;
  // The step's field could not be trusted: an error instead of the pick.
  virtual std::optional<Error> fieldError() const { return std::nullopt; }
  // The segment's target was reached; the run's counters (Bolt::stats).
  virtual void endSegment() {}
  virtual void report(Stats& /*s*/) const {}
};

std::unique_ptr<PhiMethod> fastMethod(Growth& growth, int screeningRadius);
std::unique_ptr<PhiMethod> dbmMethod(Growth& growth);
std::unique_ptr<PhiMethod> chargesMethod(Growth& growth);

// The DBM problem of a segment: the bolt so far, obstacles (and outside) at 0, the target (or
// the whole region) at 1, on the solver solver_choice.h chooses. dbm.cpp's every step, and
// the converged reference the error is measured against.
std::unique_ptr<DeepField> dbmProblem(const Growth& growth, Cell target, Solver solver);

}  // namespace effects::lightning::detail
