// Private to effects/lightning: the Dirichlet Laplace problem of DBM on a grid with fixed
// cells (bolt, obstacles: 0; target: 1; outside: 0), 5-point stencil, solved by plain CG or
// multigrid-preconditioned CG, warm-started from the previous solution.
#pragma once

#include <vector>

#include "effects/lightning.h"

namespace effects::lightning::detail {

class Laplace {
 public:
  Laplace(int width, int height);
  // Fix a cell at a value (it stops being an unknown).
  void fix(int x, int y, double value);
  // Solves to ||r|| <= tolerance * ||b|| from the current potential; returns iterations.
  int solve(Solver solver, double tolerance, double* relResidual);
  double phi(int x, int y) const { return phi_[at(x, y)]; }

 private:
  size_t at(int x, int y) const { return size_t(y + 1) * stride_ + size_t(x + 1); }
  struct Level {
    int w, h, stride;
    double scale;                 // operator = scale * (4 u - sum of 4 neighbours)
    std::vector<uint8_t> unknown;
    std::vector<double> e, r;
  };
  void buildLevels();
  void vcycle(size_t level);
  void smooth(Level& l, bool forward);
  void precondition(const std::vector<double>& r, std::vector<double>& z);

  int w_, h_, stride_;
  std::vector<double> phi_;
  std::vector<uint8_t> unknown_;  // padded; the pad is fixed at 0
  std::vector<double> r_, z_, p_, ap_;
  std::vector<Level> levels_;
  bool levelsDirty_ = true;
};

}  // namespace effects::lightning::detail
