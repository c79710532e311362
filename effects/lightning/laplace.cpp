#include "laplace.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "grid.h"

namespace effects::lightning::detail {

namespace {

constexpr int kPreSmooth = 1;  // red-black / lexicographic Gauss-Seidel sweeps per level side
constexpr int kCoarsestSweeps = 12;

}  // namespace

Laplace::Laplace(int width, int height, Parallel* parallel)
    : w_(width),
      h_(height),
      stride_(width + 2),
      parallel_(size_t(width) * size_t(height) >= kParallelCells ? parallel : nullptr) {
  size_t n = size_t(width + 2) * size_t(height + 2);
  phi_.assign(n, 0.0);
  bvec_.assign(n, 0.0);
  unknown_.assign(n, 0);
  for (int y = 0; y < h_; ++y)
    for (int x = 0; x < w_; ++x) unknown_[at(x, y)] = 1;
  for (auto* v : {&r_, &z_, &p_, &ap_}) v->assign(n, 0.0);
  levels_.resize(1);
  for (int w = w_ / 2, h = h_ / 2; w >= 2 && h >= 2; w /= 2, h /= 2) {
    Level l;
    l.w = w;
    l.h = h;
    l.stride = w + 2;
    size_t m = size_t(w + 2) * size_t(h + 2);
    l.kind.assign(m, 0);
    l.rows.assign(2, {});
    l.invDiag.assign(2, 0.0);
    l.e.assign(m, 0.0);
    l.r.assign(m, 0.0);
    levels_.push_back(std::move(l));
  }
  // Every coarse row, level by level, with nothing fixed yet; each level's regular row first.
  for (size_t k = 1; k < levels_.size(); ++k) {
    Level& l = levels_[k];
    l.rows[1] = galerkinRow(k, l.w / 2, l.h / 2);
    l.invDiag[1] = l.rows[1][4] > 0 ? 1.0 / l.rows[1][4] : 0.0;
    for (int y = 0; y < l.h; ++y)
      for (int x = 0; x < l.w; ++x) setRow(k, x, y, galerkinRow(k, x, y));
  }
  dirty_ = {0, 0, -1, -1};
}

void Laplace::fix(int x, int y, double value) {
  const size_t i = at(x, y);
  const bool wasUnknown = unknown_[i];
  const double delta = wasUnknown ? value : value - phi_[i];
  if (wasUnknown) {
    bb_ -= bvec_[i] * bvec_[i];
    bvec_[i] = 0;
    unknown_[i] = 0;
    dirty_ = dirty_.empty()
                 ? Box{x, y, x, y}
                 : Box{std::min(dirty_.x0, x), std::min(dirty_.y0, y), std::max(dirty_.x1, x), std::max(dirty_.y1, y)};
  }
  phi_[i] = value;
  if (delta != 0.0)
    for (size_t j : {i - 1, i + 1, i - size_t(stride_), i + size_t(stride_)})
      if (unknown_[j]) {
        bb_ += (bvec_[j] + delta) * (bvec_[j] + delta) - bvec_[j] * bvec_[j];
        bvec_[j] += delta;
      }
}

// One row of A_c = P^T A P at level k (k >= 1) from the operator of level k - 1.
std::array<double, 9> Laplace::galerkinRow(size_t k, int cx, int cy) const {
  const Level& c = levels_[k];
  const Level* f = k > 1 ? &levels_[k - 1] : nullptr;
  const int fw = f ? f->w : w_, fh = f ? f->h : h_, fs = f ? f->stride : stride_;
  std::array<double, 9> row{};
  for (int fy = 2 * cy; fy <= 2 * cy + 2 && fy < fh; ++fy)
    for (int fx = 2 * cx; fx <= 2 * cx + 2 && fx < fw; ++fx) {
      const size_t fi = size_t(fy + 1) * size_t(fs) + size_t(fx + 1);
      const double wf = axisWeight(fx - 2 * cx - 1) * axisWeight(fy - 2 * cy - 1);
      for (int o = 0; o < 9; ++o) {
        const int ox = o % 3 - 1, oy = o / 3 - 1;
        double a;
        if (f) {
          a = f->row(fi)[size_t(o)];
        } else {  // the fine 5-point operator on unknowns
          if (!unknown_[fi] || (ox != 0 && oy != 0)) continue;
          a = o == 4 ? 4.0 : (unknown_[fi + size_t(ox) + size_t(oy) * size_t(fs)] ? -1.0 : 0.0);
        }
        if (a == 0.0) continue;
        const int gx = fx + ox, gy = fy + oy;
        if (gx < 0 || gy < 0) continue;
        int px[2], py[2];
        double wx[2], wy[2];
        const int npx = coarseParents(gx, c.w, px, wx), npy = coarseParents(gy, c.h, py, wy);
        for (int a1 = 0; a1 < npy; ++a1)
          for (int a0 = 0; a0 < npx; ++a0)
            row[size_t((px[a0] - cx + 1) + 3 * (py[a1] - cy + 1))] += wf * a * wx[a0] * wy[a1];
      }
    }
  return row;
}

void Laplace::setRow(size_t k, int cx, int cy, const std::array<double, 9>& row) {
  Level& c = levels_[k];
  uint32_t& kind = c.kind[size_t(cy + 1) * size_t(c.stride) + size_t(cx + 1)];
  if (row == c.rows[0] || row == c.rows[1]) {  // no diagonal means no row at all (A is SPD)
    kind = row == c.rows[0] ? 0 : 1;
    return;
  }
  if (kind < 2) {  // a row of its own; one that later becomes regular again keeps its slot unused
    kind = uint32_t(c.rows.size());
    c.rows.emplace_back();
    c.invDiag.push_back(0.0);
  }
  c.rows[kind] = row;
  c.invDiag[kind] = row[4] > 0 ? 1.0 / row[4] : 0.0;
}

void Laplace::updateCoarse() {
  Box b = dirty_;
  for (size_t k = 1; k < levels_.size() && !b.empty(); ++k) {
    Level& c = levels_[k];
    // Row J changes when its fine support (2J .. 2J+2) is within one cell of a changed row.
    Box cb{std::max(0, floorDiv(b.x0 - 2, 2)), std::max(0, floorDiv(b.y0 - 2, 2)),
           std::min(c.w - 1, floorDiv(b.x1 + 1, 2)), std::min(c.h - 1, floorDiv(b.y1 + 1, 2))};
    for (int y = cb.y0; y <= cb.y1; ++y)
      for (int x = cb.x0; x <= cb.x1; ++x) setRow(k, x, y, galerkinRow(k, x, y));
    b = cb;
  }
  dirty_ = {0, 0, -1, -1};
}

void Laplace::smoothFine(bool forward, bool fromZero) {
  // Red-black Gauss-Seidel on 4e - sum e_n = r over the unknowns (e is 0 on fixed cells),
  // both colours in one pass over the rows: the second colour of row y - 1 needs only the
  // first colour of rows y - 2 .. y, so it follows the first colour of row y, and the grid
  // streams once. On threads, in blocks of rows: each block does both colours except the
  // second colour of its first and last rows, which a second pass does once every block's
  // first colour is in. Every cell sees the values it would in two whole passes, so the
  // numbers are the same on any threads.
  // From zero, the first colour's neighbours are all 0; writing every cell of both colours
  // (the pad is never written) then replaces clearing the vector.
  double* e = z_.data();
  const double* r = r_.data();
  const uint8_t* m = unknown_.data();
  const size_t s = size_t(stride_);
  const int first = forward ? 0 : 1;
  auto sweep = [&](int y, int colour) {
    const size_t row = size_t(y + 1) * s + 1;
    if (fromZero && colour == first) {
      for (int x = (y + colour) & 1; x < w_; x += 2)
        e[row + size_t(x)] = m[row + size_t(x)] ? 0.25 * r[row + size_t(x)] : 0.0;
      return;
    }
    for (int x = (y + colour) & 1; x < w_; x += 2) {
      const size_t i = row + size_t(x);
      e[i] = m[i] ? 0.25 * (r[i] + e[i - 1] + e[i + 1] + e[i - s] + e[i + s]) : 0.0;
    }
  };
  constexpr int kRows = 16;  // rows per block on threads
  const int rows = parallel_ ? kRows : h_;
  const size_t blocks = size_t((h_ + rows - 1) / rows);
  effects::forRange(parallel_, blocks, 1, [&](size_t b0, size_t b1) {
    for (size_t b = b0; b < b1; ++b) {
      const int y0 = int(b) * rows, y1 = std::min(h_, y0 + rows);
      for (int y = y0; y < y1; ++y) {
        sweep(y, first);
        if (y - 1 > y0) sweep(y - 1, 1 - first);
      }
    }
  });
  effects::forRange(parallel_, blocks, 1, [&](size_t b0, size_t b1) {
    for (size_t b = b0; b < b1; ++b) {
      const int y0 = int(b) * rows, y1 = std::min(h_, y0 + rows);
      sweep(y0, 1 - first);
      if (y1 - 1 > y0) sweep(y1 - 1, 1 - first);
    }
  });
}

void Laplace::smoothCoarse(Level& l, bool forward) {
  // Lexicographic Gauss-Seidel with the 9-point Galerkin stencil (backward on the way up, so
  // that the V-cycle is symmetric, as CG needs of a preconditioner). Only the term of the
  // previous cell in the sweep depends on the cell just updated; the rest is summed first
  // so that the loop-carried chain is one multiply-add.
  const size_t s = size_t(l.stride);
  double* e = l.e.data();
  auto update = [&](size_t i, size_t prevOffset) {
    const uint32_t kind = l.kind[i];
    const auto& a = l.rows[kind];  // all zero on inactive and pad cells, where invDiag is 0 too
    const double invDiag = l.invDiag[kind];
    const double* u = e + i - s;
    const double* d = e + i + s;
    double rest = l.r[i] - (a[0] * u[-1] + a[1] * u[0] + a[2] * u[1]) - (a[6] * d[-1] + a[7] * d[0] + a[8] * d[1]);
    // forward: e[i-1] was just updated, e[i+1] is old; backward the other way round.
    if (prevOffset == 1)
      rest -= a[5] * e[i + 1], e[i] = (rest - a[3] * e[i - 1]) * invDiag;
    else
      rest -= a[3] * e[i - 1], e[i] = (rest - a[5] * e[i + 1]) * invDiag;
  };
  if (forward) {
    for (int y = 0; y < l.h; ++y)
      for (int x = 0; x < l.w; ++x) update(size_t(y + 1) * s + size_t(x + 1), 1);
  } else {
    for (int y = l.h; y-- > 0;)
      for (int x = l.w; x-- > 0;) update(size_t(y + 1) * s + size_t(x + 1), 0);
  }
}

// e_k approximately solves A_k e_k = r_k; k = 0 is the fine level (r_ -> z_).
// Long because it is one V-cycle read top to bottom (smooth, residual, restrict, recurse,
// prolong, smooth), each step on the same level geometry (fw, fh, fs, c).
void Laplace::vcycle(size_t k) {
  const bool fine = k == 0;
  const bool coarsest = k + 1 == levels_.size();
  if (!fine) {
    Level& l = levels_[k];
    std::fill(l.e.begin(), l.e.end(), 0.0);
    if (coarsest) {
      for (int i = 0; i < kCoarsestSweeps; ++i) smoothCoarse(l, i % 2 == 0);  // symmetric pairs
      return;
    }
  }
  for (int i = 0; i < kPreSmooth; ++i) fine ? smoothFine(true, i == 0) : smoothCoarse(levels_[k], true);
  if (!coarsest) {
    // Residual of this level, restricted with P^T (full weighting over the 3x3 fine support),
    // row by row: coarse row J takes padded fine rows 2J+1 .. 2J+3, each residual row made once
    // into a ring of three (the last, row fh + 1, is the pad: 0) instead of a whole residual
    // written and read back.
    const int fw = fine ? w_ : levels_[k].w, fh = fine ? h_ : levels_[k].h;
    const size_t fs = size_t(fine ? stride_ : levels_[k].stride);
    auto residualRow = [&](int py, double* out) {  // padded row py of r - A e; 0 on the pads
      std::fill(out, out + fs, 0.0);
      if (py > fh) return;
      const size_t row = size_t(py) * fs;
      if (fine) {
        for (size_t x = 1; x <= size_t(fw); ++x) {
          const size_t i = row + x;
          out[x] = unknown_[i] ? r_[i] - (4 * z_[i] - z_[i - 1] - z_[i + 1] - z_[i - fs] - z_[i + fs]) : 0.0;
        }
      } else {
        const Level& l = levels_[k];
        const double* e = l.e.data();
        for (size_t x = 1; x <= size_t(fw); ++x) {
          const size_t i = row + x;
          const auto& a = l.row(i);
          const double* u = e + i - fs;
          const double* d = e + i + fs;
          out[x] = l.r[i] - (a[0] * u[-1] + a[1] * u[0] + a[2] * u[1]) -
                   (a[3] * e[i - 1] + a[4] * e[i] + a[5] * e[i + 1]) - (a[6] * d[-1] + a[7] * d[0] + a[8] * d[1]);
        }
      }
    };
    Level& c = levels_[k + 1];
    const size_t cs = size_t(c.stride);
    Parallel* parallel = fine ? parallel_ : nullptr;
    effects::forRange(parallel, size_t(c.h), 8, [&](size_t y0, size_t y1) {
      std::vector<double> ring(3 * fs);
      double* above = ring.data();
      double* mid = above + fs;
      double* below = mid + fs;
      residualRow(int(2 * y0 + 1), above);
      for (int cy = int(y0); cy < int(y1); ++cy) {
        residualRow(2 * cy + 2, mid);
        residualRow(2 * cy + 3, below);
        for (int cx = 0; cx < c.w; ++cx) {
          const size_t x = size_t(2 * cx + 2);  // fine cell (2cx+1, 2cy+1): padded column 2cx+2, row 2cy+2
          c.r[size_t(cy + 1) * cs + size_t(cx + 1)] =
              mid[x] + 0.5 * (mid[x - 1] + mid[x + 1] + above[x] + below[x]) +
              0.25 * (above[x - 1] + above[x + 1] + below[x - 1] + below[x + 1]);
        }
        std::swap(above, below);  // row 2cy+3 is the next coarse row's first
      }
    });
    vcycle(k + 1);
    // Prolongation (bilinear), masked to this level's active cells, gathered per fine row:
    // odd fine rows/columns sit on a coarse one, even ones halfway between two (the pad of
    // the coarse grid is 0, so the borders need no special case).
    std::vector<double>& e = fine ? z_ : levels_[k].e;
    // Active: an unknown fine cell, or a coarse cell whose row is not 0.
    const uint8_t* unknown = fine ? unknown_.data() : nullptr;
    const uint32_t* kind = fine ? nullptr : levels_[k].kind.data();
    effects::forRange(parallel, size_t(fh), 16, [&](size_t y0, size_t y1) {
      std::vector<double> line(cs);
      for (int y = int(y0); y < int(y1); ++y) {
        const double* c0 = &c.e[size_t((y + 1) / 2) * cs];  // coarse row (y-1)/2 or y/2-1, padded
        const double* c1 = &c.e[size_t(y / 2 + 1) * cs];
        const bool odd = y & 1;
        for (size_t j = 0; j < cs; ++j) line[j] = odd ? c1[j] : 0.5 * (c0[j] + c1[j]);
        const size_t row = size_t(y + 1) * fs + 1;
        for (int x = 0; x < fw; ++x) {
          const double v = (x & 1) ? line[size_t(x / 2 + 1)] : 0.5 * (line[size_t(x / 2)] + line[size_t(x / 2 + 1)]);
          const size_t i = row + size_t(x);
          if (unknown ? unknown[i] != 0 : kind[i] != 0) e[i] += v;
        }
      }
    });
  }
  for (int i = 0; i < kPreSmooth; ++i) fine ? smoothFine(false, false) : smoothCoarse(levels_[k], false);
}

void Laplace::precondition() {
  if (!dirty_.empty()) updateCoarse();
  vcycle(0);
}

std::vector<double> Laplace::preconditioned(const std::vector<double>& r) {
  for (int y = 0; y < h_; ++y)
    for (int x = 0; x < w_; ++x) r_[at(x, y)] = unknown_[at(x, y)] ? r[size_t(y) * size_t(w_) + size_t(x)] : 0.0;
  precondition();
  std::vector<double> z(r.size());
  for (int y = 0; y < h_; ++y)
    for (int x = 0; x < w_; ++x) z[size_t(y) * size_t(w_) + size_t(x)] = z_[at(x, y)];
  return z;
}

int Laplace::solve(Solver solver, double tolerance) {
  const size_t n = phi_.size();
  const size_t s = size_t(stride_);
  // r = b - A phi = (sum of 4 neighbours) - 4 phi on unknowns (fixed neighbours carry b).
  double rr = blockSum(parallel_, s, n - s, [&](size_t b, size_t e) {
    double sum = 0;
    for (size_t i = b; i < e; ++i) {
      r_[i] = unknown_[i] ? phi_[i - 1] + phi_[i + 1] + phi_[i - s] + phi_[i + s] - 4 * phi_[i] : 0.0;
      sum += r_[i] * r_[i];
    }
    return sum;
  });
  const double bnorm = bb_ > 0 ? std::sqrt(bb_) : 1.0;
  const double goal = tolerance * bnorm;
  const bool mg = solver != Solver::kCg;
  const int maxIt = 20 * (w_ + h_) + 1000;  // CG converges in O(sqrt(cond)) ~ O(n) iterations
  const int it = conjugateGradients(
      phi_, r_, z_, p_, ap_, goal, maxIt, rr, parallel_,
      [&] {
        if (mg)
          precondition();
        else
          z_ = r_;
      },
      [&] {
        return blockSum(parallel_, s, n - s, [&](size_t b, size_t e) {
          double pap = 0;
          for (size_t i = b; i < e; ++i) {
            ap_[i] =
                unknown_[i] ? 4 * p_[i] - p_[i - 1] - p_[i + 1] - p_[i - s] - p_[i + s] : 0.0;  // p is 0 on fixed cells
            pap += p_[i] * ap_[i];
          }
          return pap;
        });
      });
  residual_ = std::sqrt(rr) / bnorm;
  return it;
}

}  // namespace effects::lightning::detail
