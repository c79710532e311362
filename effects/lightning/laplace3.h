// Private to effects/lightning: the DBM potential of a 3-D grid, laplace.h's method one
// dimension up: the 7-point Laplacian over the unknown voxels (bolt, obstacles: 0, target: 1,
// outside: 0), solved by plain CG or multigrid-preconditioned CG warm-started from the previous
// solution. Coarse voxel J sits on fine voxel 2J+1 per axis; trilinear prolongation P masked
// to the unknowns, restriction P^T and Galerkin coarse operators P^T A P (27-point stencils),
// rebuilt in a box around the voxels fixed since the last solve. Smoothing: red-black
// Gauss-Seidel on the fine level, symmetric lexicographic Gauss-Seidel on the coarse ones.
#pragma once

#include <array>
#include <vector>

#include "laplace.h"

namespace effects::lightning::detail {

class Laplace3 final : public Potential {
 public:
  // parallel: where the fine level's loops may split (from kParallelCells up); null: this thread.
  Laplace3(int width, int height, int depth, Parallel* parallel = nullptr);
  Laplace3(const Laplace3&) = delete;  // levels point into themselves
  Laplace3& operator=(const Laplace3&) = delete;
  void fix(Cell c, double value) override;
  int solve(Solver solver, double tolerance) override;
  double phi(Cell c) const override { return phi_[at(c.x, c.y, c.z)]; }
  double residual() const override { return residual_; }
  size_t bytes() const;

 private:
  size_t at(int x, int y, int z) const { return (size_t(z + 1) * sy_ + size_t(y + 1)) * sx_ + size_t(x + 1); }
  struct Level {
    int w = 0, h = 0, d = 0;
    size_t sx = 0, sy = 0;                  // padded row length and rows per slab
    std::vector<std::array<double, 27>> a;  // a[i][(dx+1) + 3 (dy+1) + 9 (dz+1)]; all 0 when inactive
    // The stencil of each voxel: &interior where its row equals the row of a voxel far from
    // every fixed voxel and border (most of the grid: one row in cache instead of 27 doubles
    // read per voxel and sweep), else &a[i].
    std::array<double, 27> interior{};
    std::vector<const std::array<double, 27>*> row;
    std::vector<double> invDiag, e, r, res;  // res: this level's residual (pads stay 0)
  };
  struct Box {
    int x0, y0, z0, x1, y1, z1;  // inclusive; empty when x0 > x1
    bool empty() const { return x0 > x1 || y0 > y1 || z0 > z1; }
  };
  void galerkinRow(size_t k, int cx, int cy, int cz);
  void updateCoarse();
  void findInteriorRows();
  void vcycle(size_t k);
  void smoothFine(bool forward, bool fromZero);
  void smoothCoarse(Level& l, bool forward);
  // out = b - A phi over the unknowns; returns its squared norm.
  double residualFine(std::vector<double>& out) const;
  // The fine operator: out = A v over the unknowns; returns v . out.
  double apply(const std::vector<double>& v, std::vector<double>& out) const;

  int w_, h_, d_;
  size_t sx_, sy_;
  Parallel* parallel_;  // null below kParallelCells
  std::vector<double> phi_, bvec_, mask_, r_, z_, p_, ap_, res_;
  double bb_ = 0;        // ||b||^2, kept up to date by fix()
  double residual_ = 0;  // ||r|| / ||b|| after the last solve
  std::vector<uint8_t> unknown_;
  std::vector<Level> levels_;  // levels_[0] unused: the fine level lives in the members
  Box dirty_;
};

}  // namespace effects::lightning::detail
