#include "laplace.h"

#include <cmath>

namespace effects::lightning::detail {

Laplace::Laplace(int width, int height) : w_(width), h_(height), stride_(width + 2) {
  size_t n = size_t(width + 2) * size_t(height + 2);
  phi_.assign(n, 0.0);
  unknown_.assign(n, 0);
  for (int y = 0; y < h_; ++y)
    for (int x = 0; x < w_; ++x) unknown_[at(x, y)] = 1;
  r_.assign(n, 0.0);
  z_.assign(n, 0.0);
  p_.assign(n, 0.0);
  ap_.assign(n, 0.0);
}

void Laplace::fix(int x, int y, double value) {
  unknown_[at(x, y)] = 0;
  phi_[at(x, y)] = value;
  levelsDirty_ = true;
}

void Laplace::buildLevels() {
  // Level 0 mirrors the fine grid; a coarse block is unknown when any of its children is.
  // With block-constant prolongation P and R = P^T, the Galerkin operator R A P of
  // scale * L is 2 * scale * L on the coarse grid, hence scale doubles per level.
  if (levels_.empty()) {
    int w = w_, h = h_;
    double scale = 1.0;
    while (true) {
      Level l{w, h, w + 2, scale, {}, {}, {}};
      size_t n = size_t(w + 2) * size_t(h + 2);
      l.unknown.assign(n, 0);
      l.e.assign(n, 0.0);
      l.r.assign(n, 0.0);
      levels_.push_back(std::move(l));
      if (w <= 4 || h <= 4) break;
      w = (w + 1) / 2;
      h = (h + 1) / 2;
      scale *= 2.0;
    }
  }
  levels_[0].unknown = unknown_;
  for (size_t k = 1; k < levels_.size(); ++k) {
    Level& c = levels_[k];
    const Level& f = levels_[k - 1];
    std::fill(c.unknown.begin(), c.unknown.end(), 0);
    for (int y = 0; y < f.h; ++y)
      for (int x = 0; x < f.w; ++x)
        if (f.unknown[size_t(y + 1) * f.stride + size_t(x + 1)]) c.unknown[size_t(y / 2 + 1) * c.stride + size_t(x / 2 + 1)] = 1;
  }
  levelsDirty_ = false;
}

void Laplace::smooth(Level& l, bool forward) {
  // Red-black Gauss-Seidel on scale * (4e - sum e_n) = r; reversed colour order on the way
  // up keeps the V-cycle symmetric, as CG needs of a preconditioner.
  for (int pass = 0; pass < 2; ++pass) {
    int colour = forward ? pass : 1 - pass;
    const double inv = 1.0 / l.scale;
    for (int y = 0; y < l.h; ++y) {
      size_t row = size_t(y + 1) * l.stride;
      for (int x = (y + colour) & 1; x < l.w; x += 2) {
        size_t i = row + size_t(x + 1);
        if (!l.unknown[i]) continue;
        l.e[i] = 0.25 * (l.r[i] * inv + l.e[i - 1] + l.e[i + 1] + l.e[i - l.stride] + l.e[i + l.stride]);
      }
    }
  }
}

void Laplace::vcycle(size_t k) {
  Level& l = levels_[k];
  std::fill(l.e.begin(), l.e.end(), 0.0);
  if (k + 1 == levels_.size()) {
    for (int i = 0; i < 16; ++i) smooth(l, i % 2 == 0);  // forward/backward pairs: symmetric
    return;
  }
  smooth(l, true);
  smooth(l, true);
  Level& c = levels_[k + 1];
  std::fill(c.r.begin(), c.r.end(), 0.0);
  for (int y = 0; y < l.h; ++y)
    for (int x = 0; x < l.w; ++x) {
      size_t i = size_t(y + 1) * l.stride + size_t(x + 1);
      if (!l.unknown[i]) continue;
      double res = l.r[i] - l.scale * (4 * l.e[i] - l.e[i - 1] - l.e[i + 1] - l.e[i - l.stride] - l.e[i + l.stride]);
      c.r[size_t(y / 2 + 1) * c.stride + size_t(x / 2 + 1)] += res;
    }
  vcycle(k + 1);
  for (int y = 0; y < l.h; ++y)
    for (int x = 0; x < l.w; ++x) {
      size_t i = size_t(y + 1) * l.stride + size_t(x + 1);
      if (l.unknown[i]) l.e[i] += c.e[size_t(y / 2 + 1) * c.stride + size_t(x / 2 + 1)];
    }
  smooth(l, false);
  smooth(l, false);
}

void Laplace::precondition(const std::vector<double>& r, std::vector<double>& z) {
  if (levelsDirty_) buildLevels();
  levels_[0].r = r;
  vcycle(0);
  z = levels_[0].e;
}

int Laplace::solve(Solver solver, double tolerance, double* relResidual) {
  const size_t n = phi_.size();
  const int s = stride_;
  // b: the fixed neighbours' values; r = b - A phi = (sum of 4 neighbours) - 4 phi on unknowns.
  double bb = 0.0, rr = 0.0;
  for (size_t i = size_t(s); i + size_t(s) < n; ++i) {
    if (!unknown_[i]) {
      r_[i] = 0.0;
      continue;
    }
    double b = 0.0;
    for (size_t j : {i - 1, i + 1, i - size_t(s), i + size_t(s)})
      if (!unknown_[j]) b += phi_[j];
    bb += b * b;
    r_[i] = phi_[i - 1] + phi_[i + 1] + phi_[i - s] + phi_[i + s] - 4 * phi_[i];
    rr += r_[i] * r_[i];
  }
  const double bnorm = std::sqrt(bb) > 0 ? std::sqrt(bb) : 1.0;
  const double goal = tolerance * bnorm;
  auto apply = [&](const std::vector<double>& r, std::vector<double>& z) {
    if (solver == Solver::kMgpcg) precondition(r, z);
    else z = r;
  };
  int it = 0;
  const int maxIt = 20 * (w_ + h_) + 1000;  // CG converges in O(sqrt(cond)) ~ O(n) iterations
  if (std::sqrt(rr) > goal) {
    apply(r_, z_);
    p_ = z_;
    double rz = 0;
    for (size_t i = 0; i < n; ++i) rz += r_[i] * z_[i];
    for (; it < maxIt; ++it) {
      double pap = 0;
      for (size_t i = size_t(s); i + size_t(s) < n; ++i) {
        if (!unknown_[i]) {
          ap_[i] = 0;
          continue;
        }
        ap_[i] = 4 * p_[i] - p_[i - 1] - p_[i + 1] - p_[i - s] - p_[i + s];  // p is 0 on fixed cells
        pap += p_[i] * ap_[i];
      }
      if (!(pap > 0)) break;
      double alpha = rz / pap;
      rr = 0;
      for (size_t i = 0; i < n; ++i) {
        phi_[i] += alpha * p_[i];
        r_[i] -= alpha * ap_[i];
        rr += r_[i] * r_[i];
      }
      if (std::sqrt(rr) <= goal) {
        ++it;
        break;
      }
      apply(r_, z_);
      double rzNew = 0;
      for (size_t i = 0; i < n; ++i) rzNew += r_[i] * z_[i];
      double beta = rzNew / rz;
      rz = rzNew;
      for (size_t i = 0; i < n; ++i) p_[i] = unknown_[i] ? z_[i] + beta * p_[i] : 0.0;
    }
  }
  if (relResidual) *relResidual = std::sqrt(rr) / bnorm;
  return it;
}

}  // namespace effects::lightning::detail

namespace effects::lightning {

std::vector<double> solveLaplace(int width, int height, const std::vector<uint8_t>& obstacles,
                                 const std::vector<Cell>& bolt, Cell target, Solver solver, double tolerance,
                                 int* iterations, double* residual) {
  detail::Laplace lap(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      if (!obstacles.empty() && obstacles[size_t(y) * width + x]) lap.fix(x, y, 0.0);
  for (const Cell& c : bolt) lap.fix(c.x, c.y, 0.0);
  lap.fix(target.x, target.y, 1.0);
  int it = lap.solve(solver, tolerance, residual);
  if (iterations) *iterations = it;
  std::vector<double> out(size_t(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) out[size_t(y) * width + x] = lap.phi(x, y);
  return out;
}

}  // namespace effects::lightning
