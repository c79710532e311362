// Can a local law of eqn 8's form pick the next cell as DBM does? (issue 49, item 3.)
//
// DBM bolts are grown. At sampled steps of each, the converged Laplace field of the bolt so far
// (bolt, obstacles and border Phi = 0, target Phi = 1) gives DBM's step distribution over the
// candidates, p_i = Phi_i^eta / sum_j Phi_j^eta. A law q_i ∝ exp(eta * sum_k beta_k f_k(i)) over
// local features of the candidate is fitted to p by cross-entropy (Newton) on training bolts
// and judged by the mean total-variation distance sum_i |p_i - q_i| / 2 per step on held-out
// bolts and on other geometries (lab/layouts.h). Features:
//   G      eqn 8's steps along start -> target (folded past the target, as grow() does)
//   lnB    log of eqn 4's border/obstacle potential
//   lnP    log of eqn 5's distance to the target (at least 0.5)
//   lnN1   log of eqn 6's N: bolt cells among the 8 neighbours
//   lnN4   log(1 + bolt cells among the 4 edge neighbours): the 5-point Laplacian's own coupling
//   lnN3   log of the bolt cells within 3 cells (Chebyshev): the bolt's density around it
//   lnAge  log(1 + steps since a bolt cell last joined next to the candidate): what the fast
//          method's lifetime cuts at
//   lnLead log(1 + how far the bolt's leading cell is ahead of the candidate along the axis)
//   lnPhiC log of the Laplace field solved on a grid F times coarser (--coarse F, default 2),
//          read around the candidate (lab/half_field.h, CoarseField): the field's screening at
//          1/F^2 of the cells
//   lnNcal log of the bolt cells within the calibrated screening radius (the calibrated law's N)
//   lnFree log of the candidate's exposure (lab/exposure_law.h, exposure()): the mean length 16
//          rays travel before they meet the bolt, an obstacle or the border, capped at --reach
//          (default 16). The field's short-range screening without a solve
//   lnPgeo log of the distance to the target around the obstacles (exposure_law.h, geodesic())
//   Ggeo   the progress towards the target around the obstacles: geodesic() at the start less
//          at the candidate (G measured as the A* guide would)
// The laws compared: every candidate alike (the scale of the distances); the paper's eqn 8
// (a = 2, N adjacent, lifetime 4); the calibrated fast method (calibrate(): its base, radius and
// lifetime; candidates past the lifetime have q = 0); eqn 8's terms with fitted constants, then
// with lnAge and lnLead; the coarse field with the neighbour counts (lab/half_field.h's law);
// exposure with eqn 8's terms, with no field at all (Ggeo, lnPgeo, the counts) and with the
// coarse field; all of them. A law is a law if its constants fitted on one geometry and eta
// hold at the others.
//
//   lightning_phi_fit [--size 128] [--train 10] [--test 10] [--steps 12] [--eta 1,2,3] [--coarse 2]
//                     [--reach 16]
//
// Results and what they mean: docs/lightning-shape.md, "What a law would have to do".
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include <effects/lightning.h>

#include "lightning/hooks.h"

#include "half_field.h"
#include "layouts.h"

namespace lt = effects::lightning;

namespace {

int F = 2;  // --coarse: the coarse grid's cell, in fine cells

enum Feature {
  kG,
  kLnB,
  kLnP,
  kLnN1,
  kLnN4,
  kLnN3,
  kLnAge,
  kLnLead,
  kLnPhiC,
  kLnNcal,
  kLnFree,
  kLnPgeo,
  kGgeo,
  kFeatures
};
const char* const kNames[kFeatures] = {"G",      "lnB",    "lnP",    "lnN1",   "lnN4",   "lnN3", "lnAge",
                                       "lnLead", "lnPhiC", "lnNcal", "lnFree", "lnPgeo", "Ggeo"};

int reach = 16;  // --reach: exposure()'s cap

struct Step {
  std::vector<std::array<double, kFeatures>> f;  // per candidate
  std::vector<double> p;                         // DBM's step distribution
};

// The features of every candidate at each sampled step of DBM bolts grown in one layout.
std::vector<Step> sample(const lt::Params& layout, double eta, uint64_t firstSeed, int seeds, int stepsPerBolt) {
  std::vector<Step> out;
  const int w = layout.width, h = layout.height;
  const lt::Cell start = layout.start, target = layout.targets.at(0);
  lt::Params fast = layout;
  fast.eta = eta;
  const int calRadius = lt::calibratedScreeningRadius(fast);
  std::vector<double> lnB(size_t(w) * size_t(h), NAN);
  const std::vector<double> geo = bench::shape::geodesic(layout);
  const bench::shape::Rays rays(reach);
  double ax = target.x - start.x, ay = target.y - start.y;
  const double len = std::hypot(ax, ay);
  ax /= len;
  ay /= len;
  auto along = [&](int x, int y) { return (x - start.x) * ax + (y - start.y) * ay; };
  auto blocked = [&](int x, int y) {
    return !layout.obstacles.empty() && layout.obstacles[size_t(y) * size_t(w) + size_t(x)];
  };
  for (int s = 0; s < seeds; ++s) {
    lt::Params p = layout;
    p.method = lt::Method::kDbm;
    p.eta = eta;
    p.seed = firstSeed + uint64_t(s);
    auto bolt = lt::grow(p);
    if (!bolt.ok()) {
      std::fprintf(stderr, "dbm: %s\n", bolt.error().message.c_str());
      std::exit(1);
    }
    const auto& nodes = bolt.value().nodes;
    const int n = int(nodes.size());
    for (int k = 0; k < stepsPerBolt; ++k) {
      const int t = 4 + k * (n - 5) / stepsPerBolt;  // bolt = nodes with step < t
      std::vector<int> stepAt(size_t(w) * size_t(h), -1);
      std::vector<lt::Cell> cells;
      double lead = -INFINITY;
      for (const auto& node : nodes)
        if (node.step < t) {
          stepAt[size_t(node.cell.y) * size_t(w) + size_t(node.cell.x)] = node.step;
          cells.push_back(node.cell);
          lead = std::max(lead, along(node.cell.x, node.cell.y));
        }
      auto phi = lt::solveLaplace(w, h, layout.obstacles, cells, target, lt::Solver::kMgpcg, 1e-12);
      const bench::shape::CoarseField coarse(layout, cells, F);
      Step st;
      double maxLog = -INFINITY;
      std::vector<double> logw;
      std::vector<lt::Cell> candidates;  // free cells with a bolt cell among their 8 neighbours
      std::vector<bench::shape::Screening> screened;
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          if (stepAt[size_t(y) * size_t(w) + size_t(x)] >= 0 || blocked(x, y) || (x == target.x && y == target.y))
            continue;
          const bench::shape::Screening near = bench::shape::screening(stepAt, w, h, x, y);
          if (near.n1 == 0) continue;
          candidates.push_back({x, y});
          screened.push_back(near);
        }
      const double smallest = coarse.smallestAround(candidates);
      for (size_t i = 0; i < candidates.size(); ++i) {
        const int x = candidates[i].x, y = candidates[i].y;
        const bench::shape::Screening& near = screened[i];
        int ncal = 0;
        for (int dy = -calRadius; dy <= calRadius; ++dy)
          for (int dx = -calRadius; dx <= calRadius; ++dx) {
            const int X = x + dx, Y = y + dy;
            ncal += X >= 0 && Y >= 0 && X < w && Y < h && stepAt[size_t(Y) * size_t(w) + size_t(X)] >= 0;
          }
        const double free = bench::shape::exposure(stepAt, layout.obstacles, w, h, x, y, rays);
        double& b = lnB[size_t(y) * size_t(w) + size_t(x)];
        if (std::isnan(b)) b = std::log(lt::boundaryPotential(w, h, layout.obstacles, {x, y}));
        const double a = along(x, y);
        const double G = std::floor(a <= len ? a : 2 * len - a);
        const double P = std::max(0.5, std::hypot(double(x - target.x), double(y - target.y)));
        st.f.push_back(
            {G, b, std::log(P), std::log(double(near.n1)), std::log(1.0 + near.n4), std::log(double(near.n3)),
             std::log(1.0 + t - near.last), std::log(1.0 + std::max(0.0, lead - a)), coarse.logAround(x, y, smallest),
             std::log(double(ncal)), std::log(free), std::log(std::max(0.5, geo[size_t(y) * size_t(w) + size_t(x)])),
             geo[size_t(start.y) * size_t(w) + size_t(start.x)] - geo[size_t(y) * size_t(w) + size_t(x)]});
        const double lp = eta * std::log(std::max(phi[size_t(y) * size_t(w) + size_t(x)], 1e-300));
        logw.push_back(lp);
        maxLog = std::max(maxLog, lp);
      }
      double sum = 0;
      for (double& v : logw) sum += (v = std::exp(v - maxLog));
      for (double v : logw) st.p.push_back(v / sum);
      out.push_back(std::move(st));
    }
  }
  return out;
}

// A law: log Phi = sum_k beta[k] f_k, candidates with age > maxAge (0: none) left out.
struct Law {
  std::string name;
  std::vector<int> use;  // features fitted (empty: beta fixed)
  std::array<double, kFeatures> beta{};
  int maxAge = 0;
};

std::vector<double> distribution(const Law& law, const Step& st, double eta) {
  std::vector<double> q(st.p.size());
  double hi = -INFINITY;
  for (size_t i = 0; i < q.size(); ++i) {
    const bool expired = law.maxAge > 0 && std::exp(st.f[i][kLnAge]) - 1.0 > law.maxAge;
    double v = 0;
    for (int k = 0; k < kFeatures; ++k) v += law.beta[size_t(k)] * st.f[i][size_t(k)];
    q[i] = expired ? -INFINITY : eta * v;
    hi = std::max(hi, q[i]);
  }
  double sum = 0;
  for (double& v : q) sum += (v = std::isinf(v) ? 0.0 : std::exp(v - hi));
  for (double& v : q) v /= sum;
  return q;
}

double meanTv(const Law& law, const std::vector<Step>& steps, double eta) {
  double tv = 0;
  for (const Step& st : steps) {
    auto q = distribution(law, st, eta);
    double d = 0;
    for (size_t i = 0; i < q.size(); ++i) d += std::abs(q[i] - st.p[i]);
    tv += d / 2;
  }
  return tv / double(steps.size());
}

// Cross-entropy -sum p log q over the steps, minimised in law.use's betas by Newton's method
// with a step-halving line search.
void fit(Law& law, const std::vector<Step>& steps, double eta) {
  const size_t K = law.use.size();
  auto loss = [&](const Law& l) {
    double L = 0;
    for (const Step& st : steps) {
      auto q = distribution(l, st, eta);
      for (size_t i = 0; i < q.size(); ++i)
        if (st.p[i] > 0) L -= st.p[i] * std::log(std::max(q[i], 1e-300));
    }
    return L;
  };
  double L = loss(law);
  for (int iter = 0; iter < 50; ++iter) {
    std::vector<double> g(K, 0.0), H(K * K, 0.0);
    for (const Step& st : steps) {
      auto q = distribution(law, st, eta);
      std::vector<double> mean(K, 0.0);
      for (size_t i = 0; i < q.size(); ++i)
        for (size_t a = 0; a < K; ++a) {
          const double fa = st.f[i][size_t(law.use[a])];
          mean[a] += q[i] * fa;
          g[a] += eta * (q[i] - st.p[i]) * fa;
          for (size_t b = 0; b < K; ++b) H[a * K + b] += eta * eta * q[i] * fa * st.f[i][size_t(law.use[b])];
        }
      for (size_t a = 0; a < K; ++a)
        for (size_t b = 0; b < K; ++b) H[a * K + b] -= eta * eta * mean[a] * mean[b];
    }
    for (size_t a = 0; a < K; ++a) H[a * K + a] += 1e-9 * (1.0 + H[a * K + a]);
    // Solve H d = g (Gaussian elimination, partial pivoting).
    std::vector<double> d = g;
    for (size_t c = 0; c < K; ++c) {
      size_t piv = c;
      for (size_t r = c + 1; r < K; ++r)
        if (std::abs(H[r * K + c]) > std::abs(H[piv * K + c])) piv = r;
      for (size_t j = 0; j < K; ++j) std::swap(H[c * K + j], H[piv * K + j]);
      std::swap(d[c], d[piv]);
      for (size_t r = c + 1; r < K; ++r) {
        const double m = H[r * K + c] / H[c * K + c];
        for (size_t j = c; j < K; ++j) H[r * K + j] -= m * H[c * K + j];
        d[r] -= m * d[c];
      }
    }
    for (size_t c = K; c-- > 0;) {
      for (size_t j = c + 1; j < K; ++j) d[c] -= H[c * K + j] * d[j];
      d[c] /= H[c * K + c];
    }
    double step = 1.0;
    Law next = law;
    double Ln = L;
    for (; step > 1e-6; step /= 2) {
      next = law;
      for (size_t a = 0; a < K; ++a) next.beta[size_t(law.use[a])] -= step * d[a];
      Ln = loss(next);
      if (Ln <= L) break;
    }
    if (step <= 1e-6) break;
    const double gain = L - Ln;
    law = next;
    L = Ln;
    if (gain < 1e-9 * (1.0 + std::abs(L))) break;
  }
}

std::string betas(const Law& law) {
  std::ostringstream s;
  s.precision(3);
  for (size_t a = 0; a < law.use.size(); ++a)
    s << (a ? " " : "") << kNames[law.use[a]] << " " << law.beta[size_t(law.use[a])];
  return s.str();
}

}  // namespace

int main(int argc, char** argv) {
  int size = 128, train = 10, test = 10, steps = 12;
  std::vector<double> etas{1, 2, 3};
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--size")
      size = std::atoi(argv[i + 1]);
    else if (a == "--train")
      train = std::atoi(argv[i + 1]);
    else if (a == "--test")
      test = std::atoi(argv[i + 1]);
    else if (a == "--steps")
      steps = std::atoi(argv[i + 1]);
    else if (a == "--reach")
      reach = std::atoi(argv[i + 1]);
    else if (a == "--coarse")
      F = std::atoi(argv[i + 1]);
    else if (a == "--eta") {
      etas.clear();
      std::stringstream s(argv[i + 1]);
      for (std::string v; std::getline(s, v, ',');) etas.push_back(std::atof(v.c_str()));
    } else {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      return 2;
    }
  }
  const std::vector<std::pair<std::string, int>> others{{"off-axis", size}, {"wall", size}, {"open", size / 2}};
  for (double eta : etas) {
    const lt::Params open = bench::shape::layout("open", size);
    const auto fitSteps = sample(open, eta, 1, train, steps);
    const auto heldOut = sample(open, eta, 1001, test, steps);
    std::vector<std::vector<Step>> otherSteps;
    for (const auto& [g, s] : others) otherSteps.push_back(sample(bench::shape::layout(g, s), eta, 2001, test, steps));

    lt::Params cal = open;
    cal.eta = eta;
    lt::calibrate(cal);
    std::vector<Law> laws;
    laws.push_back({"every candidate alike (the scale)", {}, {}, 0});
    Law paper{"eqn 8 as printed (a 2, N adjacent, lifetime 4)", {}, {}, lt::kPaperLifetime};
    paper.beta = {std::log(2.0), -1, -1, -1, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    laws.push_back(paper);
    Law calibrated{"calibrated fast (a, radius, lifetime)", {}, {}, cal.lifetime};
    calibrated.beta = {std::log(cal.axisGrowth), -1, -1, 0, 0, 0, 0, 0, 0, -1, 0, 0, 0};
    laws.push_back(calibrated);
    laws.push_back({"eqn 8's terms, fitted", {kG, kLnB, kLnP, kLnN1, kLnN3}, {}, 0});
    laws.push_back({"+ lnAge", {kG, kLnB, kLnP, kLnN1, kLnN3, kLnAge}, {}, 0});
    laws.push_back({"+ lnAge + lnLead", {kG, kLnB, kLnP, kLnN1, kLnN3, kLnAge, kLnLead}, {}, 0});
    laws.push_back({"eqn 8's terms + the coarse field", {kG, kLnB, kLnP, kLnN1, kLnN3, kLnPhiC}, {}, 0});
    laws.push_back({"the coarse field and N alone", {kLnN1, kLnN3, kLnPhiC}, {}, 0});
    laws.push_back({"eqn 8's terms + edge neighbours", {kG, kLnB, kLnP, kLnN1, kLnN4, kLnN3}, {}, 0});
    laws.push_back({"the coarse field, N and edge neighbours", {kLnN1, kLnN4, kLnN3, kLnPhiC}, {}, 0});
    laws.push_back(
        {"eqn 8's terms, edge neighbours and exposure", {kG, kLnB, kLnP, kLnN1, kLnN4, kLnN3, kLnFree}, {}, 0});
    laws.push_back({"no field: Ggeo, lnPgeo, N and exposure", {kGgeo, kLnPgeo, kLnN1, kLnN4, kLnN3, kLnFree}, {}, 0});
    laws.push_back(
        {"the coarse field, N, edge neighbours and exposure", {kLnPhiC, kLnN1, kLnN4, kLnN3, kLnFree}, {}, 0});
    laws.push_back({"all of them", {kG, kLnB, kLnP, kLnN1, kLnN4, kLnN3, kLnAge, kLnLead, kLnPhiC}, {}, 0});
    std::printf("\n## eta %g: fitted on open %d^2 (%d bolts x %d steps), TV per step\n\n", eta, size, train, steps);
    std::printf(
        "| law | open (fit) | open (held out) | off-axis %d | wall %d | open %d | constants "
        "|\n|---|---|---|---|---|---|---|\n",
        size, size, size / 2);
    for (Law& law : laws) {
      if (!law.use.empty()) fit(law, fitSteps, eta);
      std::printf("| %s | %.3f | %.3f |", law.name.c_str(), meanTv(law, fitSteps, eta), meanTv(law, heldOut, eta));
      for (const auto& o : otherSteps) std::printf(" %.3f |", meanTv(law, o, eta));
      std::printf(" %s |\n", law.use.empty() ? "fixed" : betas(law).c_str());
      std::fflush(stdout);
    }
    // Refitted on each other geometry: do the constants move?
    for (size_t g = 0; g < others.size(); ++g)
      for (const std::vector<int>& use :
           {std::vector<int>{kG, kLnB, kLnP, kLnN1, kLnN3}, std::vector<int>{kLnN1, kLnN4, kLnN3, kLnPhiC},
            std::vector<int>{kGgeo, kLnPgeo, kLnN1, kLnN4, kLnN3, kLnFree}}) {
        Law law{"", use, {}, 0};
        fit(law, otherSteps[g], eta);
        std::printf("refit on %s %d: TV %.3f, %s\n", others[g].first.c_str(), others[g].second,
                    meanTv(law, otherSteps[g], eta), betas(law).c_str());
      }
  }
}
