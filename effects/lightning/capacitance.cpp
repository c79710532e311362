// DBM's potential by the capacitance-matrix method (capacitance.h), 2-D and 3-D.
#include "capacitance.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "laplace3.h"
#include "map_cache.h"

namespace effects::lightning::detail {

// The series runs over the n cells of the shorter axis (coordinate s = 1..n with the pad at 0
// and n + 1): the 5-point operator's eigenvectors there are sin(theta_k s), theta_k =
// pi k / (n + 1), k = 1..n, with squared norm (n + 1) / 2. Along the other axis (t = 1..m)
// each mode leaves the 1-D operator d_k u_t - u_(t-1) - u_(t+1), d_k = 2 + 2 (1 - cos theta_k)
// = 2 cosh mu_k, whose Green's function is
//   g_k(t, t') = [cosh(mu_k (M - |t - t'|)) - cosh(mu_k (M - (t + t')))] / (2 sinh mu_k sinh(mu_k M)),
// M = m + 1. With sin a sin b = [cos(a - b) - cos(a + b)] / 2,
//   G = K(|s - s'|, |t - t'|) - K(s + s', |t - t'|) - K(|s - s'|, t + t') + K(s + s', t + t'),
//   K(ds, dt) = 1 / (n + 1) sum_k cos(theta_k ds) h_k(dt),
//   h_k(d) = cosh(mu_k (M - d)) / (2 sinh mu_k sinh(mu_k M))
//          = (e^(-mu_k d) + e^(-mu_k (2M - d))) / (2 sinh mu_k (1 - e^(-2 mu_k M)))  (no overflow).
namespace {
// cos(pi j / (n + 1)) for j = 0 .. 2n + 1: a sine series' cosines, indexed (k d) mod 2 (n + 1).
std::vector<double> cosines(int n) {
  std::vector<double> c(size_t(2 * (n + 1)));
  for (size_t j = 0; j < c.size(); ++j) c[j] = std::cos(M_PI * double(j) / (n + 1));
  return c;
}
// 2 sin^2(theta_k / 2), theta_k = pi k / (n + 1): mode k's part of cosh mu - 1 (no cancellation).
double halfSquared(int k, int n) {
  const double half = std::sin(M_PI * k / (2.0 * (n + 1)));
  return 2 * half * half;
}
// h(d), d = 0 .. 2m, of the closed-form axis (m cells, M = m + 1) for cosh mu = 1 + delta.
void closedForm(double delta, int m, double* h) {
  const int M = m + 1;
  const double mu = std::log1p(delta + std::sqrt(delta * (delta + 2)));
  const double scale = 1.0 / (2 * std::sinh(mu) * -std::expm1(-2 * mu * M));
  for (int d = 0; d <= 2 * m; ++d) h[d] = (std::exp(-mu * d) + std::exp(-mu * (2 * M - d))) * scale;
}
// Mode k of a series over n cells: row r of `out` (r = 0 .. 2n, `stride` entries each) gains
// cos(theta_k r) / divisor times `in`.
void addMode(const std::vector<double>& cosine, int k, int n, double divisor, const double* in, size_t stride,
             double* out) {
  for (int r = 0; r <= 2 * n; ++r) {
    const double c = cosine[size_t((k * r) % (2 * (n + 1)))] / divisor;
    double* row = out + size_t(r) * stride;
    for (size_t i = 0; i < stride; ++i) row[i] += c * in[i];
  }
}
}  // namespace

BoxGreen::BoxGreen(int width, int height, int depth, Parallel* parallel) : volume_(depth > 0) {
  if (!volume_) {
    order_[0] = height < width ? 1 : 0, order_[1] = -1, order_[2] = height < width ? 0 : 1;
    const int n = std::min(width, height), m = std::max(width, height);
    stride2_ = 1, stride_ = size_t(2 * m + 1);
    const std::vector<double> cosine = cosines(n);
    // Every mode's closed form (cosh mu = 2 - cos theta_k), then K by blocks of rows that stay
    // in cache while the modes add to them in order: the same sums as mode by mode over the
    // whole table, which streamed all of it from memory once a mode. The blocks split over the
    // threads (a 1024^2 table: 1.8 s before, 1.35 s on one thread, 0.8 s on two).
    std::vector<double> h(size_t(n) * stride_);
    forRange(parallel, size_t(n), 16, [&](size_t b, size_t e) {
      for (size_t k = b; k < e; ++k) closedForm(halfSquared(int(k) + 1, n), m, &h[k * stride_]);
    });
    const size_t rows = size_t(2 * n + 1), period = size_t(2 * (n + 1));
    constexpr size_t kRowsPerBlock = 16;
    k_.assign(rows * stride_, 0.0);
    forRange(parallel, (rows + kRowsPerBlock - 1) / kRowsPerBlock, 1, [&](size_t b, size_t e) {
      for (size_t r0 = b * kRowsPerBlock; r0 < std::min(rows, e * kRowsPerBlock); r0 += kRowsPerBlock)
        for (size_t k = 1; k <= size_t(n); ++k) {
          const double* in = &h[(k - 1) * stride_];
          for (size_t r = r0; r < std::min(rows, r0 + kRowsPerBlock); ++r) {
            const double c = cosine[(k * r) % period] / (n + 1);
            double* row = &k_[r * stride_];
            for (size_t i = 0; i < stride_; ++i) row[i] += c * in[i];
          }
        }
    });
    return;
  }
  // 3-D: the series over the two shorter axes (n1, n2 cells), the closed form along the
  // longest (m): per mode pair cosh mu = 1 + 2 sin^2(theta_k / 2) + 2 sin^2(phi_l / 2), and
  //   K(d1, d2, dt) = 1 / ((n1 + 1)(n2 + 1)) sum_k,l cos(theta_k d1) cos(phi_l d2) h_kl(dt),
  // summed as B_k(d2, dt) = sum_l cos(phi_l d2) h_kl(dt), then K += cos(theta_k d1) B_k.
  const int len[3] = {width, height, depth};
  int ax[3] = {0, 1, 2};
  std::stable_sort(ax, ax + 3, [&](int a, int b) { return len[a] < len[b]; });
  std::copy(ax, ax + 3, order_);
  const int n1 = len[ax[0]], n2 = len[ax[1]], m = len[ax[2]];
  stride2_ = size_t(2 * n2 + 1), stride_ = size_t(2 * m + 1);
  const std::vector<double> cos1 = cosines(n1), cos2 = cosines(n2);
  const size_t plane = stride2_ * stride_;
  k_.assign(size_t(2 * n1 + 1) * plane, 0.0);
  std::vector<double> b(plane), h(stride_);
  for (int k = 1; k <= n1; ++k) {
    std::fill(b.begin(), b.end(), 0.0);
    for (int l = 1; l <= n2; ++l) {
      closedForm(halfSquared(k, n1) + halfSquared(l, n2), m, h.data());
      addMode(cos2, l, n2, 1.0, h.data(), stride_, b.data());
    }
    addMode(cos1, k, n1, double(n1 + 1) * double(n2 + 1), b.data(), plane, k_.data());
  }
}

size_t BoxGreen::tableEntries(int width, int height, int depth) {
  int len[3] = {width, height, depth};
  std::sort(len, len + (depth > 0 ? 3 : 2));
  size_t n = 1;
  for (int i = 0; i < (depth > 0 ? 3 : 2); ++i) n *= size_t(2 * len[i] + 1);
  return n;
}

double BoxGreen::operator()(Cell a, Cell b) const {
  const int ta = axis(a, 2), tb = axis(b, 2);
  const size_t dt = size_t(std::abs(ta - tb)), st = size_t(ta + tb);
  const int sa = axis(a, 0), sb = axis(b, 0);
  if (!volume_) {
    const size_t ds = size_t(std::abs(sa - sb)) * stride_, ss = size_t(sa + sb) * stride_;
    return (k_[ds + dt] - k_[ss + dt]) - (k_[ds + st] - k_[ss + st]);
  }
  const int ra = axis(a, 1), rb = axis(b, 1);
  const size_t plane = stride2_ * stride_;
  const size_t d1 = size_t(std::abs(sa - sb)) * plane, s1 = size_t(sa + sb) * plane;
  const size_t d2 = size_t(std::abs(ra - rb)) * stride_, s2 = size_t(ra + rb) * stride_;
  auto axes = [&](size_t t) { return (k_[d1 + d2 + t] - k_[s1 + d2 + t]) - (k_[d1 + s2 + t] - k_[s1 + s2 + t]); };
  return axes(dt) - axes(st);
}

std::shared_ptr<const BoxGreen> cachedBoxGreen(int width, int height, int depth, Parallel* parallel) {
  // Keyed as a map of depth -1 - depth with no obstacles: a table depends on the grid size only.
  return std::static_pointer_cast<const BoxGreen>(cachedMap(
      width, height, -1 - depth, {}, nullptr,
      [&] { return std::make_shared<const BoxGreen>(width, height, depth, parallel); },
      [](const void* t) { return static_cast<const BoxGreen*>(t)->bytes(); }));
}

namespace {
// a . b. Two vectors of four partial sums (AVX2 where the CPU has it, chosen at load time):
// a sum's additions no longer wait on each other. The order is fixed, so the value is too.
using Four = double __attribute__((vector_size(32)));
__attribute__((target_clones("avx2", "default"))) double dot(const double* a, const double* b, size_t n) {
  Four s0{}, s1{};
  size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    Four a0, a1, b0, b1;
    std::memcpy(&a0, a + i, sizeof a0), std::memcpy(&a1, a + i + 4, sizeof a1);
    std::memcpy(&b0, b + i, sizeof b0), std::memcpy(&b1, b + i + 4, sizeof b1);
    s0 += a0 * b0, s1 += a1 * b1;
  }
  s0 += s1;
  double s = (s0[0] + s0[1]) + (s0[2] + s0[3]);
  for (; i < n; ++i) s += a[i] * b[i];
  return s;
}
size_t rowStart(size_t i) { return i * (i + 1) / 2; }
}  // namespace

namespace {
constexpr double kSynchronousVolume = 64.0 * 64.0 * 64.0;  // the service's synchronous 3-D solver limit
}

size_t Capacitance::maxFixed(int width, int height, int depth) {
  if (depth > 0) {
    // Up to 64^3, 1024, where a step cost a few milliseconds against MGPCG's tens. Past it (jobs)
    // a fixed cell has about ten candidates, nearly all of which the bounded draw computes in
    // 3-D, so a step streams about 11 m^2 numbers against MGPCG's hundreds of bytes a cell
    // (4096 fixed cells: 0.1 s against MGPCG's 0.29 s a step at 128^3): cells^(2/3) / 4,
    // continuous at 64^3, at most 4096 (maxBytes: 800 MB).
    const double cells = double(width) * double(height) * double(depth);
    if (cells <= kSynchronousVolume) return 1024;
    return std::min<size_t>(size_t(0.25 * std::cbrt(cells) * std::cbrt(cells)), 4096);
  }
  const double cells = double(width) * double(height);
  // Up to 256^2 (the service's synchronous limit) MGPCG's grid stays in cache, and the two
  // measured even at about 4.5 sqrt(cells) (64^2-256^2), at most 1024. Past it both stream from
  // memory, a step of this one the rows and L (O(m^2)), MGPCG's the grid's levels several times
  // over: at 512^2 and 1024^2 a direct step at 6 sqrt(cells) fixed cells costs about what an
  // MGPCG step does (docs/lightning-hero.md). At most 8192 (maxBytes: 3 GiB).
  if (cells <= 65536.0) return std::clamp<size_t>(size_t(4.5 * std::sqrt(cells)), 64, 1024);
  return std::min<size_t>(size_t(6 * std::sqrt(cells)), 8192);
}

size_t Capacitance::maxBytes(int width, int height, int depth) {
  const size_t m = maxFixed(width, height, depth);
  if (depth > 0) return std::max(size_t(64) << 20, 6 * m * m * sizeof(double));
  return 6 * m * m * sizeof(double);
}

bool Capacitance::fits(int width, int height, int depth) {
  if (depth <= 0) return true;
  const double cells = double(width) * double(height) * double(depth);
  const size_t cap = cells <= kSynchronousVolume ? size_t(32) << 20 : size_t(256) << 20;
  return BoxGreen::tableEntries(width, height, depth) * sizeof(double) <= cap;
}

Capacitance::Capacitance(int width, int height, int depth, Parallel* parallel)
    : w_(width),
      h_(height),
      d_(depth),
      parallel_(parallel),
      maxFixed_(maxFixed(width, height, depth)),
      maxBytes_(maxBytes(width, height, depth)),
      green_(cachedBoxGreen(width, height, depth, parallel)),
      fixedIndex_(size_t(width) * size_t(height) * size_t(std::max(depth, 1))),
      rowOf_(size_t(width) * size_t(height) * size_t(std::max(depth, 1))) {}

Capacitance::Row& Capacitance::reserve(Cell c) const {
  const size_t i = at(c);
  int slot = rowOf_.get(i);
  if (slot < 0) {
    slot = int(rows_.size());
    rowOf_.set(i, slot);
    rows_.emplace_back();
  }
  Row& r = rows_[size_t(slot)];
  while (r.blocks.size() * kBlock < fixed_.size()) {
    if (blocks_ % kBlocksPerPage == 0) pages_.emplace_back(new double[kBlocksPerPage * kBlock]);
    r.blocks.push_back(blocks_++);
  }
  return r;
}

void Capacitance::fill(Row& r, Cell c) const {
  for (; r.size < fixed_.size(); ++r.size)
    block(r.blocks[r.size / kBlock])[r.size % kBlock] = (*green_)(c, fixed_[r.size]);
}

double Capacitance::dotQ(const Row& r, size_t n) const {
  double s = 0;
  for (size_t b = 0; b * kBlock < n; ++b) s += dot(block(r.blocks[b]), &q_[b * kBlock], std::min(kBlock, n - b * kBlock));
  return s;
}

void Capacitance::forward(double* x, size_t n) const {
  double partial[kSolveBlock];
  for (size_t b0 = 0; b0 < n; b0 += kSolveBlock) {
    const size_t b1 = std::min(n, b0 + kSolveBlock);
    // Threads only where a block's products are worth handing out (tens of microseconds).
    forRange(b0 >= 4 * kSolveBlock ? parallel_ : nullptr, b1 - b0, 16, [&](size_t s, size_t e) {
      for (size_t i = s; i < e; ++i) partial[i] = dot(&lower_[rowStart(b0 + i)], x, b0);
    });
    for (size_t i = b0; i < b1; ++i) {
      const double* row = &lower_[rowStart(i)];
      x[i] = (x[i] - partial[i - b0] - dot(row + b0, x + b0, i - b0)) / row[i];
    }
  }
}

void Capacitance::backward(double* x, size_t n) const {
  // By rows p of L from the last: x_p, then x_i -= L_pi x_p for i < p.
  for (size_t b1 = n; b1 > 0;) {
    const size_t b0 = b1 > kSolveBlock ? b1 - kSolveBlock : 0;
    for (size_t p = b1; p-- > b0;) {
      const double* l = &lower_[rowStart(p)];
      const double xp = x[p] /= l[p];
      for (size_t i = b0; i < p; ++i) x[i] -= l[i] * xp;
    }
    forRange(b0 >= 4 * kSolveBlock ? parallel_ : nullptr, b0, 512, [&](size_t s, size_t e) {
      for (size_t p = b1; p-- > b0;) {
        const double* l = &lower_[rowStart(p)];
        const double xp = x[p];
        for (size_t i = s; i < e; ++i) x[i] -= l[i] * xp;
      }
    });
    b1 = b0;
  }
}

void Capacitance::handOver() {
  if (d_ > 0)
    fallback_ = std::make_unique<Laplace3>(w_, h_, d_, parallel_);
  else
    fallback_ = std::make_unique<Laplace>(w_, h_, parallel_);
  for (size_t j = 0; j < fixed_.size(); ++j) fallback_->fix(fixed_[j], value_[j]);
  // What only the direct solve needed goes.
  for (auto* v : {&lower_, &y_, &q_}) std::vector<double>().swap(*v);
  std::vector<Row>().swap(rows_);
  std::vector<std::unique_ptr<double[]>>().swap(pages_);
  rowOf_ = CellIndex();
}

void Capacitance::fix(Cell c, double value) {
  if (fallback_) return fallback_->fix(c, value);
  const size_t cell = at(c);
  if (const int j = fixedIndex_.get(cell); j >= 0) {  // a new value: y again from v
    value_[size_t(j)] = value;
    y_ = value_;
    forward(y_.data(), y_.size());
    return;
  }
  if (fixed_.size() >= maxFixed_ || (size_t(blocks_) * kBlock + lower_.capacity()) * sizeof(double) > maxBytes_) {
    handOver();
    return fallback_->fix(c, value);
  }
  // C gains the row g = G(c, fixed cells) and the diagonal G(c, c): L's new row l solves
  // L l = g, its diagonal is sqrt(G(c, c) - l . l), and y gains (v - l . y) / that.
  const size_t m = fixed_.size();
  const Row& g = row(c);
  if (lower_.empty()) lower_.reserve(rowStart(maxFixed_ + 1));  // no copies as it grows
  lower_.resize(rowStart(m + 1));
  double* l = &lower_[rowStart(m)];
  for (size_t i = 0; i < m; ++i) l[i] = entry(g, i);
  forward(l, m);
  const double d = (*green_)(c, c) - dot(l, l, m);
  // C is positive definite (G is the inverse of a positive definite operator); d is G of c
  // with the other fixed cells grounded, positive for any cell not yet fixed.
  if (!(d > 1e-12 * (*green_)(c, c))) {
    lower_.resize(rowStart(m));
    handOver();
    return fallback_->fix(c, value);
  }
  l[m] = std::sqrt(d);
  y_.push_back((value - dot(l, y_.data(), m)) / l[m]);
  fixed_.push_back(c);
  value_.push_back(value);
  fixedIndex_.set(cell, int(m));
}

int Capacitance::solve(Solver solver, double tolerance) {
  if (fallback_) return fallback_->solve(solver, tolerance);
  q_ = y_;
  backward(q_.data(), q_.size());
  return 0;
}

double Capacitance::phi(Cell c) const {
  if (fallback_) return fallback_->phi(c);
  if (const int j = fixedIndex_.get(at(c)); j >= 0) return value_[size_t(j)];
  return dotQ(row(c), q_.size());
}

void Capacitance::phiAt(const std::vector<Cell>& cells, std::vector<double>& out, const uint8_t* which) {
  if (fallback_) return fallback_->phiAt(cells, out, which);
  out.resize(cells.size());
  // The rows and their blocks first, on this thread (rows_ and the pool grow), listed with the
  // cells that want a value: the entries and the dot products then split over the threads, a
  // row to a thread.
  todo_.clear();
  for (size_t i = 0; i < cells.size(); ++i) {
    const size_t cell = at(cells[i]);
    if (const int j = fixedIndex_.get(cell); j >= 0) {
      out[i] = value_[size_t(j)];
    } else {
      reserve(cells[i]);
      if (!which || which[i]) todo_.emplace_back(i, size_t(rowOf_.get(cell)));
    }
  }
  forRange(parallel_, todo_.size(), 64, [&](size_t b, size_t e) {
    for (size_t k = b; k < e; ++k) {
      const auto [i, slot] = todo_[k];
      Row& r = rows_[slot];
      fill(r, cells[i]);
      out[i] = dotQ(r, q_.size());
    }
  });
}

// ||C q - v|| / ||v|| over the fixed cells: the grid equations elsewhere hold by
// construction of G, to its rounding. C is symmetric and the row of the k-th fixed cell holds
// C_kj for j < k (what it had when it was fixed), so C q needs no new values of G but the
// diagonal.
double Capacitance::residual() const {
  if (fallback_) return fallback_->residual();
  const size_t m = q_.size();
  std::vector<double> cq(m, 0.0);
  for (size_t k = 0; k < m; ++k) {
    const Row& r = rows_[size_t(rowOf_.get(at(fixed_[k])))];
    for (size_t j = 0; j < std::min(k, r.size); ++j) {
      const double c = entry(r, j);
      cq[j] += c * q_[k];
      cq[k] += c * q_[j];
    }
    cq[k] += (*green_)(fixed_[k], fixed_[k]) * q_[k];
  }
  double rr = 0, vv = 0;
  for (size_t j = 0; j < m; ++j) rr += (cq[j] - value_[j]) * (cq[j] - value_[j]), vv += value_[j] * value_[j];
  return vv > 0 ? std::sqrt(rr / vv) : std::sqrt(rr);
}

}  // namespace effects::lightning::detail

namespace effects::lightning {

size_t capacitanceBytes(int width, int height, int depth) {
  if (!detail::Capacitance::fits(width, height, depth)) return 0;
  return detail::Capacitance::maxBytes(width, height, depth) +
         detail::BoxGreen::tableEntries(width, height, depth) * sizeof(double);
}

}  // namespace effects::lightning
