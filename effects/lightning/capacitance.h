// Private to effects/lightning: DBM's Dirichlet problem (laplace.h, laplace3.h) solved directly by
// the capacitance-matrix method (Buzbee, Dorr, George & Golub 1971; Proskurowski & Widlund
// 1976): the potential is a sum of point sources at the fixed cells,
//   phi(x) = sum_j q_j G(x, x_j),
// with G the Green's function of the 5-point (7-point in 3-D) Laplacian on the whole box (0
// outside), which is
// known in closed form. The charges q solve C q = v, C_ij = G(x_i, x_j), v the fixed values,
// so phi is the exact solution of the same discrete problem Laplace solves iteratively. DBM
// fixes one cell a step: C grows by a row, its Cholesky factor by a row (O(m^2)), and phi at
// the candidates is a dot product over the m fixed cells. docs/effects.md section 1.3.
#pragma once

#include <memory>
#include <utility>
#include <vector>

#include "grid.h"
#include "laplace.h"

namespace effects::lightning::detail {

// G(a, b) of a width x height (x depth) grid, A G(., b) = e_b with A the 5-point operator (4
// on the diagonal; in 3-D the 7-point one, 6) and 0 outside. A sine series along the shorter
// axis (the two shorter axes) times the longest axis's 1-D Green's functions in closed form;
// the products of sines and of hyperbolic functions fold into one table K of
// (2 n1 + 1) (x (2 n2 + 1)) x (2 m + 1) entries, so that G is four lookups (eight in 3-D).
class BoxGreen {
 public:
  // depth 0: a 2-D grid. parallel: where a 2-D table's rows split as it is built.
  BoxGreen(int width, int height, int depth = 0, Parallel* parallel = nullptr);
  double operator()(Cell a, Cell b) const;
  size_t bytes() const { return k_.size() * sizeof(double); }
  static size_t tableEntries(int width, int height, int depth = 0);

 private:
  // A cell's coordinates along the series axes and the closed-form axis, from 1 (0 and
  // length + 1 are the pad).
  int axis(Cell c, int k) const { return (order_[k] == 0 ? c.x : order_[k] == 1 ? c.y : c.z) + 1; }
  int order_[3];      // series axis 1, series axis 2 (3-D), closed-form axis: 0 x, 1 y, 2 z
  bool volume_;       // 3-D
  size_t stride2_;    // 2 n2 + 1 (3-D)
  size_t stride_;     // 2 m + 1
  std::vector<double> k_;
};

// The table of a grid size, kept beside the boundary maps (map_cache.h).
std::shared_ptr<const BoxGreen> cachedBoxGreen(int width, int height, int depth = 0, Parallel* parallel = nullptr);

class Capacitance final : public Potential {
 public:
  // A step costs O(m^2) here (the two triangular solves, and phi at the candidates the bounded
  // draw asks for, each a dot product over the m fixed cells) and O(cells) in MGPCG: past
  // maxFixed() fixed cells the problem goes to Laplace (MGPCG at the request's tolerance). Up
  // to 256^2 about 4.5 sqrt(cells), where the two measured even (bolts at 64^2-256^2 handed
  // over at several limits, every candidate computed), at most 1024; past it 6 sqrt(cells), at
  // most 8192 (about even at 512^2 and 1024^2, every candidate computed:
  // docs/lightning-hero.md). In 3-D up to 64^3: 1024, where a step still costs a few
  // milliseconds against MGPCG's tens; past it cells^(2/3) / 4, at most 4096.
  static size_t maxFixed(int width, int height, int depth = 0);
  // Working memory at most: the Cholesky factor (maxFixed^2 / 2 entries) and the rows (about
  // 4 maxFixed^2 at the limit: ~3 candidates and the cell itself per fixed cell), 6 maxFixed^2
  // entries in all; rows beyond that hand over too. In 3-D (~10 candidates per bolt voxel
  // with 26 neighbours) 64 MB up to 64^3, 6 maxFixed^2 entries past it.
  static size_t maxBytes(int width, int height, int depth = 0);
  // Whether a grid's table is small enough to build (every 2-D grid up to the solver's cell
  // limit; 3-D up to 64^3 a table of at most 32 MB, past it (jobs) 256 MB: 128^3's is 136 MB).
  static bool fits(int width, int height, int depth);

  // parallel: where phiAt's cells split (and the solver it hands over to); null: this thread.
  Capacitance(int width, int height, int depth = 0, Parallel* parallel = nullptr);
  // Rows of the triangular solves' blocks (forward, backward); from 4 blocks they use threads.
  static constexpr size_t kSolveBlock = 256;
  void fix(Cell c, double value) override;
  int solve(Solver solver, double tolerance) override;
  double phi(Cell c) const override;
  // Every cell's row is kept (made if new, with room for an entry per fixed cell) whether or
  // not which asks for it, so that the memory that hands a bolt over does not depend on it.
  void phiAt(const std::vector<Cell>& cells, std::vector<double>& out, const uint8_t* which = nullptr) override;
  double residual() const override;
  bool direct() const override { return !fallback_; }

 private:
  // G from a cell to the fixed cells, in the order they were fixed, kept per cell asked about
  // (candidates and fixed cells) and extended as cells are fixed; stored in blocks of kBlock
  // entries from a pool that only grows (no copies as rows lengthen).
  static constexpr size_t kBlock = 64;
  struct Row {
    std::vector<uint32_t> blocks;  // pool blocks holding entries kBlock b .. kBlock (b + 1) - 1
    size_t size = 0;
  };
  // A cell's row, made if new, with pool blocks for an entry per fixed cell (serial: the pool
  // grows); fill() computes the entries it lacks (a row at a time, so rows fill in parallel).
  Row& reserve(Cell c) const;
  void fill(Row& r, Cell c) const;
  Row& row(Cell c) const {
    Row& r = reserve(c);
    fill(r, c);
    return r;
  }
  double* block(uint32_t b) const { return pages_[b / kBlocksPerPage].get() + (b % kBlocksPerPage) * kBlock; }
  double entry(const Row& r, size_t j) const { return block(r.blocks[j / kBlock])[j % kBlock]; }
  size_t at(Cell c) const { return (size_t(c.z) * size_t(h_) + size_t(c.y)) * size_t(w_) + size_t(c.x); }
  // Row . q over the first n fixed cells.
  double dotQ(const Row& r, size_t n) const;
  void handOver();
  // L x = b and L^T x = b over the first n fixed cells, in place (x holds b), in blocks of
  // kSolveBlock rows whose products with the entries outside the block split over the threads.
  // No value depends on the threads: forward's dot products split at the block's first row
  // whatever runs them, and backward takes each entry's terms in the order a whole-matrix
  // sweep does.
  void forward(double* x, size_t n) const;
  void backward(double* x, size_t n) const;
  static constexpr size_t kBlocksPerPage = 64;

  int w_, h_, d_;  // d_ 0: 2-D
  Parallel* parallel_;
  size_t maxFixed_, maxBytes_;
  std::shared_ptr<const BoxGreen> green_;
  std::vector<Cell> fixed_;
  std::vector<double> value_;
  CellIndex fixedIndex_;
  std::vector<double> lower_;   // Cholesky factor of C, row by row (row i has i + 1 entries)
  std::vector<double> y_;       // L y = v
  std::vector<double> q_;       // L^T q = y, from the last solve
  mutable CellIndex rowOf_;
  mutable std::vector<Row> rows_;
  mutable std::vector<std::unique_ptr<double[]>> pages_;
  mutable uint32_t blocks_ = 0;  // pool blocks handed out
  std::vector<std::pair<size_t, size_t>> todo_;  // phiAt's cells to compute: (index, row slot)
  std::unique_ptr<Potential> fallback_;
};

}  // namespace effects::lightning::detail
