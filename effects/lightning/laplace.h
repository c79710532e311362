// Private to effects/lightning: the Dirichlet Laplace problem of DBM on a grid with fixed
// cells (bolt, obstacles: 0; target: 1; outside: 0), 5-point stencil, solved by plain CG or
// multigrid-preconditioned CG, warm-started from the previous solution.
//
// The multigrid is algebraic in its coarse operators: vertex-centred coarsening (coarse cell
// J sits on fine cell 2J+1), bilinear prolongation P masked to the unknown fine cells,
// restriction P^T and Galerkin coarse operators A_c = P^T A P (9-point stencils). Fixed cells
// inside the grid — a one-cell-wide bolt — are seen exactly by every coarse level, which a
// re-discretised coarse grid cannot do. Fixing a cell changes A_c only near it, so the
// coarse rows are rebuilt in a small box per level instead of from scratch every step.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "effects/lightning.h"
#include "effects/parallel.h"

namespace effects::lightning::detail {

// Threads help the fine level's loops from this many cells up (below, a V-cycle is too short
// to pay for handing out work): 512^2 in 2-D, 64^3 in 3-D. Set by that reasoning, not tuned
// (docs/lightning-hero.md has what two threads gain at 512^2 and 1024^2).
inline constexpr size_t kParallelCells = size_t(512) * 512;

// The same numbers on any number of threads: loops over a range split into fixed blocks of
// kBlock indices (never the pool's own chunks), and sums add the blocks' partial sums in
// block order. One block (ranges up to kBlock) is the plain loop, bit for bit.
inline constexpr size_t kBlock = 16384;
template <class Fn>
void blockFor(Parallel* parallel, size_t first, size_t last, Fn fn) {
  if (last <= first) return;
  const size_t blocks = (last - first + kBlock - 1) / kBlock;
  auto run = [&](size_t b0, size_t b1) {
    for (size_t b = b0; b < b1; ++b) fn(first + b * kBlock, std::min(last, first + (b + 1) * kBlock));
  };
  if (!parallel || blocks == 1) return run(0, blocks);
  effects::forRange(parallel, blocks, 1, run);
}
// sum over blocks of fn(begin, end), a block's own sum, in block order.
template <class Fn>
double blockSum(Parallel* parallel, size_t first, size_t last, Fn fn) {
  if (last <= first) return 0;
  const size_t blocks = (last - first + kBlock - 1) / kBlock;
  if (blocks == 1) return fn(first, last);
  std::vector<double> part(blocks);
  blockFor(parallel, first, last, [&](size_t b, size_t e) { part[(b - first) / kBlock] = fn(b, e); });
  double sum = 0;
  for (double v : part) sum += v;
  return sum;
}

// Vertex-centred coarsening, per axis (2-D and 3-D alike): coarse cell J sits on fine cell 2J+1.
inline int floorDiv(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }
// Bilinear weight of the coarse cell sitting on fine cell c for fine cell f, per axis (d = f - c).
inline double axisWeight(int d) { return d == 0 ? 1.0 : 0.5; }
// Coarse parents (index, weight) of fine cell g along one axis of n coarse cells: an odd g
// sits on one (weight 1), an even g lies between two (1/2 each). Returns how many.
inline int coarseParents(int g, int n, int* p, double* w) {
  int np = 0;
  if (g & 1) {
    if ((g - 1) / 2 < n) p[np] = (g - 1) / 2, w[np++] = 1.0;
  } else {
    if (g / 2 - 1 >= 0 && g / 2 - 1 < n) p[np] = g / 2 - 1, w[np++] = 0.5;
    if (g / 2 < n) p[np] = g / 2, w[np++] = 0.5;
  }
  return np;
}

// Conjugate gradients from phi with residual r (r = b - A phi, rr = its squared norm) until
// ||r|| <= goal or maxIt iterations; precondition() sets z from r, applyAndDot() sets
// ap = A p and returns p . ap. The vectors share one padded layout (pads stay 0). The vector
// loops run on `parallel` (null: this thread) in fixed blocks. Returns the iterations; rr ends
// as the final residual's squared norm.
template <class Precondition, class ApplyAndDot>
int conjugateGradients(std::vector<double>& phi, std::vector<double>& r, std::vector<double>& z, std::vector<double>& p,
                       const std::vector<double>& ap, double goal, int maxIt, double& rr, Parallel* parallel,
                       Precondition precondition, ApplyAndDot applyAndDot) {
  const size_t n = phi.size();
  auto dotRz = [&](size_t b, size_t e) {
    double sum = 0;
    for (size_t i = b; i < e; ++i) sum += r[i] * z[i];
    return sum;
  };
  int it = 0;
  if (!(std::sqrt(rr) > goal)) return 0;
  precondition();
  blockFor(parallel, 0, n, [&](size_t b, size_t e) {
    std::copy(z.begin() + ptrdiff_t(b), z.begin() + ptrdiff_t(e), p.begin() + ptrdiff_t(b));
  });
  double rz = blockSum(parallel, 0, n, dotRz);
  for (; it < maxIt; ++it) {
    const double pap = applyAndDot();
    if (!(pap > 0)) break;
    const double alpha = rz / pap;
    rr = blockSum(parallel, 0, n, [&](size_t b, size_t e) {
      double sum = 0;
      for (size_t i = b; i < e; ++i) {
        phi[i] += alpha * p[i];
        r[i] -= alpha * ap[i];
        sum += r[i] * r[i];
      }
      return sum;
    });
    if (std::sqrt(rr) <= goal) return it + 1;
    precondition();
    const double rzNew = blockSum(parallel, 0, n, dotRz);
    const double beta = rzNew / rz;
    rz = rzNew;
    blockFor(parallel, 0, n, [&](size_t b, size_t e) {
      for (size_t i = b; i < e; ++i) p[i] = z[i] + beta * p[i];  // z is 0 on fixed cells
    });
  }
  return it;
}

// The DBM potential of a 2-D grid (Laplace) or a 3-D one (Laplace3, laplace3.h).
class Potential {
 public:
  virtual ~Potential() = default;
  // Fix a cell at a value (it stops being an unknown).
  virtual void fix(Cell c, double value) = 0;
  // Solves to ||r|| <= tolerance * ||b|| from the current potential; returns iterations.
  virtual int solve(Solver solver, double tolerance) = 0;
  virtual double phi(Cell c) const = 0;
  // Phi at many cells (a step's candidates): out[i] = phi(cells[i]), where which is null or
  // which[i] is set (out[i] is left as it was elsewhere). The direct solver computes them on
  // its threads; a cell's value does not depend on how they are split, nor on which others
  // are asked for.
  virtual void phiAt(const std::vector<Cell>& cells, std::vector<double>& out, const uint8_t* which = nullptr) {
    out.resize(cells.size());
    for (size_t i = 0; i < cells.size(); ++i)
      if (!which || which[i]) out[i] = phi(cells[i]);
  }
  // The relative residual the last solve reached.
  virtual double residual() const = 0;
  // Whether the last solve was direct (capacitance.h) rather than iterative.
  virtual bool direct() const { return false; }
};

class Laplace final : public Potential {
 public:
  // parallel: where the fine level's loops may split (from kParallelCells up); null: this thread.
  Laplace(int width, int height, Parallel* parallel = nullptr);
  void fix(int x, int y, double value);
  void fix(Cell c, double value) override { fix(c.x, c.y, value); }
  int solve(Solver solver, double tolerance) override;
  double phi(int x, int y) const { return phi_[at(x, y)]; }
  double phi(Cell c) const override { return phi(c.x, c.y); }
  double residual() const override { return residual_; }
  // One V-cycle, z = M r, over unpadded w x h vectors (r's entries on fixed cells are ignored,
  // z is 0 there), for tests: CG needs M symmetric. Uses the solver's scratch vectors.
  std::vector<double> preconditioned(const std::vector<double>& r);

 private:
  size_t at(int x, int y) const { return size_t(y + 1) * stride_ + size_t(x + 1); }
  // A coarse level: padded (w+2) x (h+2) arrays. Cell i's stencil is rows[kind[i]], where
  // row[k] is the weight from the cell to its neighbour at offset k = (dx+1) + 3 (dy+1).
  // Most cells share one row: rows[0] is all zero (inactive and pad cells), rows[1] the
  // level's regular row (its centre's before anything was fixed; rows equal to it bit for bit
  // point at it), and only cells near a border or a fixed cell have rows of their own. A cell
  // then streams 4 bytes of stencil per sweep instead of 72 (+8 of diagonal).
  struct Level {
    int w = 0, h = 0, stride = 0;
    std::vector<uint32_t> kind;
    std::vector<std::array<double, 9>> rows;
    std::vector<double> invDiag;  // per row: 1 / its diagonal, 0 for rows[0]
    std::vector<double> e, r;
    const std::array<double, 9>& row(size_t i) const { return rows[kind[i]]; }
  };
  struct Box {
    int x0, y0, x1, y1;  // inclusive; empty when x0 > x1
    bool empty() const { return x0 > x1 || y0 > y1; }
  };
  void updateCoarse();
  std::array<double, 9> galerkinRow(size_t k, int cx, int cy) const;
  void setRow(size_t k, int cx, int cy, const std::array<double, 9>& row);
  void vcycle(size_t k);
  void smoothFine(bool forward, bool fromZero);
  void smoothCoarse(Level& l, bool forward);
  void precondition();

  int w_, h_, stride_;
  Parallel* parallel_;  // null below kParallelCells
  std::vector<double> phi_, bvec_;
  std::vector<uint8_t> unknown_;  // padded: 1 on unknowns, 0 on fixed and pad cells (a byte, not
                                  // a double mask: the fine loops are bound by memory traffic)
  double bb_ = 0;                 // ||b||^2, kept up to date by fix()
  double residual_ = 0;           // ||r|| / ||b|| after the last solve
  std::vector<double> r_, z_, p_, ap_;
  std::vector<Level> levels_;  // levels_[0] is unused: the fine level lives in the members
  Box dirty_;                  // fine cells fixed since the coarse operators were built
};

}  // namespace effects::lightning::detail
