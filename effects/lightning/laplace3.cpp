#include "laplace3.h"

#include <algorithm>
#include <cmath>

namespace effects::lightning::detail {

namespace {

constexpr int kCoarsestSweeps = 12;

// Offsets of the 27-point stencil in a padded level with rows of sx and slabs of sx * sy.
std::array<ptrdiff_t, 27> offsets(size_t sx, size_t sy) {
  std::array<ptrdiff_t, 27> o{};
  for (int k = 0; k < 27; ++k)
    o[size_t(k)] =
        ptrdiff_t(k % 3 - 1) + ptrdiff_t(k / 3 % 3 - 1) * ptrdiff_t(sx) + ptrdiff_t(k / 9 - 1) * ptrdiff_t(sx * sy);
  return o;
}

// sum_k a[k] * centre[off[k]] over the 27-point stencil, in nine row sums added pairwise: a
// 27-long chain of dependent additions made the coarse sweeps wait on the adder, not memory.
inline double stencilDot(const std::array<double, 27>& a, const double* centre, const std::array<ptrdiff_t, 27>& off) {
  double row[9];
  for (size_t j = 0; j < 9; ++j)
    row[j] =
        a[3 * j] * centre[off[3 * j]] + a[3 * j + 1] * centre[off[3 * j + 1]] + a[3 * j + 2] * centre[off[3 * j + 2]];
  return (((row[0] + row[1]) + (row[2] + row[3])) + ((row[4] + row[5]) + (row[6] + row[7]))) + row[8];
}

}  // namespace

Laplace3::Laplace3(int width, int height, int depth, Parallel* parallel)
    : w_(width),
      h_(height),
      d_(depth),
      sx_(size_t(width) + 2),
      sy_(size_t(height) + 2),
      parallel_(size_t(width) * size_t(height) * size_t(depth) >= kParallelCells ? parallel : nullptr) {
  const size_t n = sx_ * sy_ * (size_t(depth) + 2);
  phi_.assign(n, 0.0);
  bvec_.assign(n, 0.0);
  mask_.assign(n, 0.0);
  unknown_.assign(n, 0);
  for (auto* v : {&r_, &z_, &p_, &ap_, &res_}) v->assign(n, 0.0);
  for (int z = 0; z < d_; ++z)
    for (int y = 0; y < h_; ++y)
      for (int x = 0; x < w_; ++x) unknown_[at(x, y, z)] = 1, mask_[at(x, y, z)] = 1.0;
  levels_.resize(1);
  for (int w = w_ / 2, h = h_ / 2, d = d_ / 2; w >= 2 && h >= 2 && d >= 2; w /= 2, h /= 2, d /= 2) {
    Level l;
    l.w = w, l.h = h, l.d = d;
    l.sx = size_t(w) + 2, l.sy = size_t(h) + 2;
    const size_t m = l.sx * l.sy * (size_t(d) + 2);
    l.a.assign(m, {});
    l.row.assign(m, nullptr);
    for (auto* v : {&l.invDiag, &l.e, &l.r, &l.res}) v->assign(m, 0.0);
    levels_.push_back(std::move(l));
  }
  for (Level& l : levels_)
    for (size_t i = 0; i < l.a.size(); ++i) l.row[i] = &l.a[i];
  dirty_ = {0, 0, 0, w_ - 1, h_ - 1, d_ - 1};
  findInteriorRows();
}

// Builds every coarse row while nothing is fixed and takes each level's interior row: the row
// of its centre voxel. Rows are computed the same way everywhere, so a row far from fixed
// voxels and borders equals it bit for bit; such rows point at it, here and in galerkinRow().
void Laplace3::findInteriorRows() {
  updateCoarse();
  for (size_t k = 1; k < levels_.size(); ++k) {
    Level& l = levels_[k];
    l.interior = l.a[(size_t(l.d / 2 + 1) * l.sy + size_t(l.h / 2 + 1)) * l.sx + size_t(l.w / 2 + 1)];
    for (size_t i = 0; i < l.a.size(); ++i)
      if (l.a[i] == l.interior) l.row[i] = &l.interior;
  }
}

size_t Laplace3::bytes() const {
  size_t b = phi_.size() * (8 * sizeof(double) + 1);
  for (const Level& l : levels_) b += l.a.size() * (sizeof(l.a[0]) + sizeof(l.row[0]) + 4 * sizeof(double));
  return b;
}

void Laplace3::fix(Cell c, double value) {
  const size_t i = at(c.x, c.y, c.z);
  const bool wasUnknown = unknown_[i];
  const double delta = wasUnknown ? value : value - phi_[i];
  if (wasUnknown) {
    bb_ -= bvec_[i] * bvec_[i];
    bvec_[i] = 0;
    unknown_[i] = 0;
    mask_[i] = 0.0;
    dirty_ = dirty_.empty() ? Box{c.x, c.y, c.z, c.x, c.y, c.z}
                            : Box{std::min(dirty_.x0, c.x), std::min(dirty_.y0, c.y), std::min(dirty_.z0, c.z),
                                  std::max(dirty_.x1, c.x), std::max(dirty_.y1, c.y), std::max(dirty_.z1, c.z)};
  }
  phi_[i] = value;
  if (delta != 0.0)
    for (size_t j : {i - 1, i + 1, i - sx_, i + sx_, i - sx_ * sy_, i + sx_ * sy_})
      if (unknown_[j]) {
        bb_ += (bvec_[j] + delta) * (bvec_[j] + delta) - bvec_[j] * bvec_[j];
        bvec_[j] += delta;
      }
}

// One row of A_c = P^T A P at level k (k >= 1) from the operator of level k - 1.
void Laplace3::galerkinRow(size_t k, int cx, int cy, int cz) {
  Level& c = levels_[k];
  const Level* f = k > 1 ? &levels_[k - 1] : nullptr;
  const int fw = f ? f->w : w_, fh = f ? f->h : h_, fd = f ? f->d : d_;
  const size_t fsx = f ? f->sx : sx_, fsy = f ? f->sy : sy_;
  std::array<double, 27> row{};
  for (int fz = 2 * cz; fz <= 2 * cz + 2 && fz < fd; ++fz)
    for (int fy = 2 * cy; fy <= 2 * cy + 2 && fy < fh; ++fy)
      for (int fx = 2 * cx; fx <= 2 * cx + 2 && fx < fw; ++fx) {
        const size_t fi = (size_t(fz + 1) * fsy + size_t(fy + 1)) * fsx + size_t(fx + 1);
        const double wf = axisWeight(fx - 2 * cx - 1) * axisWeight(fy - 2 * cy - 1) * axisWeight(fz - 2 * cz - 1);
        for (int o = 0; o < 27; ++o) {
          const int ox = o % 3 - 1, oy = o / 3 % 3 - 1, oz = o / 9 - 1;
          double a;
          if (f) {
            a = (*f->row[fi])[size_t(o)];
          } else {  // the fine 7-point operator on unknowns
            if (!unknown_[fi] || std::abs(ox) + std::abs(oy) + std::abs(oz) > 1) continue;
            const ptrdiff_t off = ptrdiff_t(ox) + ptrdiff_t(oy) * ptrdiff_t(fsx) + ptrdiff_t(oz) * ptrdiff_t(fsx * fsy);
            a = o == 13 ? 6.0 : (unknown_[size_t(ptrdiff_t(fi) + off)] ? -1.0 : 0.0);
          }
          if (a == 0.0) continue;
          const int gx = fx + ox, gy = fy + oy, gz = fz + oz;
          if (gx < 0 || gy < 0 || gz < 0) continue;
          int px[2], py[2], pz[2];
          double wx[2], wy[2], wz[2];
          const int npx = coarseParents(gx, c.w, px, wx), npy = coarseParents(gy, c.h, py, wy),
                    npz = coarseParents(gz, c.d, pz, wz);
          for (int a2 = 0; a2 < npz; ++a2)
            for (int a1 = 0; a1 < npy; ++a1)
              for (int a0 = 0; a0 < npx; ++a0)
                row[size_t((px[a0] - cx + 1) + 3 * (py[a1] - cy + 1) + 9 * (pz[a2] - cz + 1))] +=
                    wf * a * wx[a0] * wy[a1] * wz[a2];
        }
      }
  const size_t ci = (size_t(cz + 1) * c.sy + size_t(cy + 1)) * c.sx + size_t(cx + 1);
  c.a[ci] = row;
  c.row[ci] = row == c.interior ? &c.interior : &c.a[ci];
  c.invDiag[ci] = row[13] > 0 ? 1.0 / row[13] : 0.0;
}

void Laplace3::updateCoarse() {
  Box b = dirty_;
  for (size_t k = 1; k < levels_.size() && !b.empty(); ++k) {
    Level& c = levels_[k];
    // Row J changes when its fine support (2J .. 2J+2) is within one voxel of a changed row.
    Box cb{std::max(0, floorDiv(b.x0 - 2, 2)),       std::max(0, floorDiv(b.y0 - 2, 2)),
           std::max(0, floorDiv(b.z0 - 2, 2)),       std::min(c.w - 1, floorDiv(b.x1 + 1, 2)),
           std::min(c.h - 1, floorDiv(b.y1 + 1, 2)), std::min(c.d - 1, floorDiv(b.z1 + 1, 2))};
    for (int z = cb.z0; z <= cb.z1; ++z)
      for (int y = cb.y0; y <= cb.y1; ++y)
        for (int x = cb.x0; x <= cb.x1; ++x) galerkinRow(k, x, y, z);
    b = cb;
  }
  dirty_ = {0, 0, 0, -1, -1, -1};
}

void Laplace3::smoothFine(bool forward, bool fromZero) {
  // Red-black Gauss-Seidel on 6e - sum e_n = r over the unknowns (e is 0 on fixed voxels).
  // A colour's voxels depend only on the other colour's, so its pass splits over slabs on
  // threads with the same numbers.
  // From zero, the first colour's neighbours are all 0; writing every voxel of both colours
  // (the pad is never written) then replaces clearing the vector.
  const size_t slab = sx_ * sy_;
  double* e = z_.data();
  for (int pass = 0; pass < 2; ++pass) {
    const int colour = forward ? pass : 1 - pass;
    effects::forRange(parallel_, size_t(d_), 1, [&](size_t z0, size_t z1) {
      for (int z = int(z0); z < int(z1); ++z)
        for (int y = 0; y < h_; ++y) {
          const size_t row = (size_t(z + 1) * sy_ + size_t(y + 1)) * sx_ + 1;
          if (fromZero && pass == 0) {
            for (int x = (y + z + colour) & 1; x < w_; x += 2)
              e[row + size_t(x)] = mask_[row + size_t(x)] * (1.0 / 6.0) * r_[row + size_t(x)];
            continue;
          }
          for (int x = (y + z + colour) & 1; x < w_; x += 2) {
            const size_t i = row + size_t(x);
            // Added pairwise, not as one chain of six dependent additions.
            e[i] = mask_[i] * (1.0 / 6.0) *
                   ((r_[i] + (e[i - 1] + e[i + 1])) + ((e[i - sx_] + e[i + sx_]) + (e[i - slab] + e[i + slab])));
          }
        }
    });
  }
}

void Laplace3::smoothCoarse(Level& l, bool forward) {
  // Lexicographic Gauss-Seidel with the 27-point Galerkin stencil, in place (backward on the
  // way up, so that the V-cycle is symmetric, as CG needs of a preconditioner).
  const auto off = offsets(l.sx, l.sy);
  double* e = l.e.data();
  auto update = [&](size_t i) {
    const auto& a = *l.row[i];
    // All 27 terms, the centre's added back: no branch in the loop.
    e[i] = (l.r[i] - stencilDot(a, e + i, off) + a[13] * e[i]) * l.invDiag[i];
  };
  if (forward) {
    for (int z = 0; z < l.d; ++z)
      for (int y = 0; y < l.h; ++y)
        for (int x = 0; x < l.w; ++x) update((size_t(z + 1) * l.sy + size_t(y + 1)) * l.sx + size_t(x + 1));
  } else {
    for (int z = l.d; z-- > 0;)
      for (int y = l.h; y-- > 0;)
        for (int x = l.w; x-- > 0;) update((size_t(z + 1) * l.sy + size_t(y + 1)) * l.sx + size_t(x + 1));
  }
}

double Laplace3::apply(const std::vector<double>& v, std::vector<double>& out) const {
  // Over every index between the pad slabs (pad voxels have mask 0: out stays 0 there).
  const size_t slab = sx_ * sy_;
  return blockSum(parallel_, slab, v.size() - slab, [&](size_t b, size_t end) {
    double dot = 0;
    for (size_t i = b; i < end; ++i) {
      out[i] = mask_[i] * (6 * v[i] - v[i - 1] - v[i + 1] - v[i - sx_] - v[i + sx_] - v[i - slab] - v[i + slab]);
      dot += v[i] * out[i];
    }
    return dot;
  });
}

// e_k approximately solves A_k e_k = r_k; k = 0 is the fine level (r_ -> z_).
// Long because it is one V-cycle read top to bottom (smooth, residual, restrict, recurse,
// prolong, smooth), each step on the same level geometry.
void Laplace3::vcycle(size_t k) {
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
  fine ? smoothFine(true, true) : smoothCoarse(levels_[k], true);
  if (!coarsest) {
    const int fw = fine ? w_ : levels_[k].w, fh = fine ? h_ : levels_[k].h, fd = fine ? d_ : levels_[k].d;
    const size_t fsx = fine ? sx_ : levels_[k].sx, fsy = fine ? sy_ : levels_[k].sy;
    // This level's residual into its own buffer, whose padding stays 0 (restriction reads it).
    std::vector<double>& res = fine ? res_ : levels_[k].res;
    if (fine) {
      const size_t slab = sx_ * sy_;
      const double* v = z_.data();
      blockFor(parallel_, slab, res.size() - slab, [&](size_t b, size_t end) {
        for (size_t i = b; i < end; ++i)
          res[i] = mask_[i] * (r_[i] - mask_[i] * (6 * v[i] - v[i - 1] - v[i + 1] - v[i - sx_] - v[i + sx_] -
                                                   v[i - slab] - v[i + slab]));
      });
    } else {
      const Level& l = levels_[k];
      const auto off = offsets(l.sx, l.sy);
      for (int z = 0; z < l.d; ++z)
        for (int y = 0; y < l.h; ++y)
          for (int x = 0; x < l.w; ++x) {
            const size_t i = (size_t(z + 1) * l.sy + size_t(y + 1)) * l.sx + size_t(x + 1);
            res[i] = l.r[i] - stencilDot(*l.row[i], l.e.data() + i, off);
          }
    }
    // Restriction P^T: full weighting over the 3x3x3 fine voxels around 2J+1, separably
    // (along x, then y, then z, each [1/2, 1, 1/2]).
    Level& c = levels_[k + 1];
    const size_t fslab = fsx * fsy;
    Parallel* parallel = fine ? parallel_ : nullptr;
    effects::forRange(parallel, size_t(c.d), 1, [&](size_t z0, size_t z1) {
      for (int cz = int(z0); cz < int(z1); ++cz)
        for (int cy = 0; cy < c.h; ++cy)
          for (int cx = 0; cx < c.w; ++cx) {
            const size_t i = (size_t(2 * cz + 2) * fsy + size_t(2 * cy + 2)) * fsx + size_t(2 * cx + 2);
            auto row = [&](size_t j) { return 0.5 * res[j - 1] + res[j] + 0.5 * res[j + 1]; };
            auto plane = [&](size_t j) { return 0.5 * row(j - fsx) + row(j) + 0.5 * row(j + fsx); };
            c.r[(size_t(cz + 1) * c.sy + size_t(cy + 1)) * c.sx + size_t(cx + 1)] =
                0.5 * plane(i - fslab) + plane(i) + 0.5 * plane(i + fslab);
          }
    });
    vcycle(k + 1);
    // Prolongation (trilinear), masked to this level's active voxels, one fine row at a time:
    // the coarse rows around it blended in y and z (the coarse padding is 0, so borders need
    // no case), then along x: an odd fine x sits on coarse voxel (x-1)/2, an even one between
    // x/2-1 and x/2 (padded indices x/2 + 1 and x/2).
    std::vector<double>& e = fine ? z_ : levels_[k].e;
    const std::vector<double>& active = fine ? mask_ : levels_[k].invDiag;
    effects::forRange(parallel, size_t(fd), 1, [&](size_t z0, size_t z1) {
      std::vector<double> line(c.sx);
      for (int z = int(z0); z < int(z1); ++z) {
        int pz[2];
        double wz[2];
        const int nz = coarseParents(z, c.d, pz, wz);
        for (int y = 0; y < fh; ++y) {
          int py[2];
          double wy[2];
          const int ny = coarseParents(y, c.h, py, wy);
          std::fill(line.begin(), line.end(), 0.0);
          for (int a2 = 0; a2 < nz; ++a2)
            for (int a1 = 0; a1 < ny; ++a1) {
              const double wgt = wz[a2] * wy[a1];
              const double* src = &c.e[(size_t(pz[a2] + 1) * c.sy + size_t(py[a1] + 1)) * c.sx];
              for (size_t j = 0; j < c.sx; ++j) line[j] += wgt * src[j];
            }
          const size_t row = (size_t(z + 1) * fsy + size_t(y + 1)) * fsx + 1;
          for (int x = 0; x < fw; ++x) {
            const size_t i = row + size_t(x);
            if (active[i] == 0.0) continue;
            e[i] += (x & 1) ? line[size_t(x / 2 + 1)] : 0.5 * (line[size_t(x / 2)] + line[size_t(x / 2 + 1)]);
          }
        }
      }
    });
  }
  fine ? smoothFine(false, false) : smoothCoarse(levels_[k], false);
}

double Laplace3::residualFine(std::vector<double>& out) const {
  const size_t slab = sx_ * sy_;
  return blockSum(parallel_, slab, out.size() - slab, [&](size_t b, size_t end) {
    double sum = 0;
    for (size_t i = b; i < end; ++i) {
      out[i] = mask_[i] * (phi_[i - 1] + phi_[i + 1] + phi_[i - sx_] + phi_[i + sx_] + phi_[i - slab] + phi_[i + slab] -
                           6 * phi_[i]);
      sum += out[i] * out[i];
    }
    return sum;
  });
}

int Laplace3::solve(Solver solver, double tolerance) {
  // r = b - A phi = (sum of 6 neighbours) - 6 phi on unknowns (fixed neighbours carry b).
  double rr = residualFine(r_);
  const double bnorm = bb_ > 0 ? std::sqrt(bb_) : 1.0;
  const double goal = tolerance * bnorm;
  const bool mg = solver != Solver::kCg && levels_.size() > 1;
  const int maxIt = 20 * (w_ + h_ + d_) + 1000;
  auto precondition = [&] {
    if (mg) {
      if (!dirty_.empty()) updateCoarse();
      vcycle(0);
    } else {
      z_ = r_;
    }
  };
  const int it = conjugateGradients(phi_, r_, z_, p_, ap_, goal, maxIt, rr, parallel_, precondition,
                                    [&] { return apply(p_, ap_); });
  residual_ = std::sqrt(rr) / bnorm;
  return it;
}

}  // namespace effects::lightning::detail
