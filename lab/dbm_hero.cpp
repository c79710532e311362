// dbm_hero: exact DBM hero bolts at large grids (docs/lightning-hero.md), in one run:
//   1. a bolt per grid side (top centre to bottom centre, eta 2, 8 neighbours, MGPCG at the
//      default tolerance 1e-6, seed 1): seconds, cells, steps, V-cycles, and a hash of the
//      cells in growth order (the same hash means the same bolt, cell for cell);
//   2. the same bolt on two threads (Params::parallel), whose hash must equal the first's; at
//      sizes up to 256^2 also the capacitance direct solver's (no multigrid in it), the peer
//      measured in the same run;
//   3. exactness at sampled steps (1/4, 1/2, 3/4 of the bolt): the step solved as growth
//      solves it (the bolt up to the step's cell solved to the tolerance, the cell fixed, a
//      warm solve to the tolerance) against the same bolt solved from scratch to 1e-12: the
//      candidates' largest error relative to their largest potential P, and the total
//      variation distance between the two candidate distributions Phi^eta / sum.
// Usage: dbm_hero [side ...]   (default 256 512 1024). Exit 1 when two solvers' bolts differ.
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "effects/lightning.h"
#include "lightning/deep_field.h"
#include "lightning/laplace.h"
#include "lightning/solver_choice.h"

namespace lt = effects::lightning;
namespace ld = effects::lightning::detail;

namespace {

constexpr double kEta = 2.0;
constexpr double kTolerance = 1e-6;

lt::Params layout(int side, lt::Solver solver) {
  lt::Params p;
  p.width = p.height = side;
  p.start = {side / 2, 0};
  p.targets = {{side / 2, side - 1}};
  p.method = lt::Method::kDbm;
  p.solver = solver;
  p.eta = kEta;
  p.tolerance = kTolerance;
  p.neighbourhood = 8;
  p.seed = 1;
  return p;
}

uint64_t hashOf(const lt::Bolt& b) {  // FNV-1a over the cells in growth order
  uint64_t h = 1469598103934665603ull;
  for (const lt::Node& n : b.nodes)
    for (int v : {n.cell.x, n.cell.y}) h = (h ^ uint64_t(uint32_t(v))) * 1099511628211ull;
  return h;
}

struct Run {
  lt::Bolt bolt;
  double seconds = 0;
};

Run grow(int side, lt::Solver solver, effects::Parallel* parallel = nullptr) {
  lt::Params p = layout(side, solver);
  p.parallel = parallel;
  const auto t0 = std::chrono::steady_clock::now();
  auto r = lt::grow(p);
  Run run;
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!r.ok()) {
    std::fprintf(stderr, "grow %d: %s\n", side, r.error().message.c_str());
    std::exit(2);
  }
  run.bolt = std::move(r.value());
  return run;
}

// The free 8-neighbours of the first n cells: the candidates of step n.
std::vector<lt::Cell> candidates(const lt::Bolt& b, size_t n, int side) {
  std::vector<uint8_t> bolt(size_t(side) * size_t(side), 0), seen(bolt.size(), 0);
  for (size_t i = 0; i < n; ++i) bolt[size_t(b.nodes[i].cell.y) * size_t(side) + size_t(b.nodes[i].cell.x)] = 1;
  std::vector<lt::Cell> out;
  const lt::Cell target{side / 2, side - 1};
  for (size_t i = 0; i < n; ++i)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int x = b.nodes[i].cell.x + dx, y = b.nodes[i].cell.y + dy;
        if (x < 0 || y < 0 || x >= side || y >= side) continue;
        const size_t k = size_t(y) * size_t(side) + size_t(x);
        if (bolt[k] || seen[k] || (x == target.x && y == target.y)) continue;
        seen[k] = 1;
        out.push_back({x, y});
      }
  return out;
}

std::unique_ptr<ld::DeepField> problem(const lt::Bolt& b, size_t n, int side) {
  auto f = std::make_unique<ld::DeepField>(ld::potentialFor(side, side, 0, lt::Solver::kMgpcg, n + 1, n + 1), side, side, 0);
  for (size_t i = 0; i < n; ++i) f->fix(b.nodes[i].cell, 0.0);
  f->fix({side / 2, side - 1}, 1.0);
  return f;
}

// Step n (its bolt: the first n cells) as growth solves it, against a converged solve.
void sampledStep(const lt::Bolt& b, size_t n, int side) {
  const std::vector<lt::Cell> probes = candidates(b, n, side);
  std::vector<double> logPhi, refLogPhi;
  auto warm = problem(b, n - 1, side);
  warm->solve(lt::Solver::kMgpcg, kTolerance, candidates(b, n - 1, side), logPhi);
  warm->fix(b.nodes[n - 1].cell, 0.0);
  const auto t0 = std::chrono::steady_clock::now();
  const int its = warm->solve(lt::Solver::kMgpcg, kTolerance, probes, logPhi);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  problem(b, n, side)->solve(lt::Solver::kMgpcg, 1e-12, probes, refLogPhi);
  double P = 0, err = 0, sum = 0, refSum = 0;
  for (size_t i = 0; i < probes.size(); ++i) P = std::max(P, std::exp(refLogPhi[i]));
  for (size_t i = 0; i < probes.size(); ++i) {
    err = std::max(err, std::fabs(std::exp(logPhi[i]) - std::exp(refLogPhi[i])) / P);
    sum += std::exp(kEta * logPhi[i]);
    refSum += std::exp(kEta * refLogPhi[i]);
  }
  double tv = 0;
  for (size_t i = 0; i < probes.size(); ++i)
    tv += std::fabs(std::exp(kEta * logPhi[i]) / sum - std::exp(kEta * refLogPhi[i]) / refSum);
  std::printf("  step %6zu: %5zu candidates, P %.3e, warm solve %3d V-cycles %7.1f ms, error/P %.2e, TV %.2e\n", n,
              probes.size(), P, its, ms, err, 0.5 * tv);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> sides;
  for (int i = 1; i < argc; ++i) sides.push_back(std::atoi(argv[i]));
  if (sides.empty()) sides = {256, 512, 1024};
  int status = 0;
  effects::ThreadPool pool(1);  // the caller and one worker: this machine's two cores
  std::printf("exact DBM, top centre to bottom centre, eta %.0f, 8 neighbours, MGPCG at %.0e, seed 1\n", kEta, kTolerance);
  for (int side : sides) {
    const Run mg = grow(side, lt::Solver::kMgpcg);
    const effects::Stats& s = mg.bolt.stats;
    std::printf("%4d^2: %8.2f s  %6zu cells  %6.0f steps  %7.0f V-cycles (%.2f a step)  D %.3f  hash %016" PRIx64 "\n",
                side, mg.seconds, mg.bolt.nodes.size(), s.counters.at("steps"), s.counters.at("solverIterations"),
                s.counters.at("solverIterations") / s.counters.at("steps"),
                lt::fractalDimension([&] {
                  std::vector<lt::Cell> c;
                  for (const lt::Node& n : mg.bolt.nodes) c.push_back(n.cell);
                  return c;
                }(), side, side),
                hashOf(mg.bolt));
    {
      const Run two = grow(side, lt::Solver::kMgpcg, &pool);
      const bool same = hashOf(two.bolt) == hashOf(mg.bolt);
      std::printf("        on 2 threads:         %8.2f s, hash %016" PRIx64 " (%s), 1 thread / 2 threads %.2fx%s\n",
                  two.seconds, hashOf(two.bolt), same ? "the same bolt" : "A DIFFERENT BOLT", mg.seconds / two.seconds,
                  size_t(side) * size_t(side) < ld::kParallelCells ? " (one thread below 512^2)" : "");
      if (!same) status = 1;
    }
    if (side <= 256) {
      const Run cap = grow(side, lt::Solver::kCapacitance);
      const bool same = hashOf(cap.bolt) == hashOf(mg.bolt);
      std::printf("        capacitance (direct): %8.2f s, hash %016" PRIx64 " (%s), MGPCG / direct %.2fx\n", cap.seconds,
                  hashOf(cap.bolt), same ? "the same bolt" : "A DIFFERENT BOLT", mg.seconds / cap.seconds);
      if (!same) status = 1;
    }
    const size_t n = mg.bolt.nodes.size();
    for (size_t q = 1; q <= 3; ++q) sampledStep(mg.bolt, std::max<size_t>(2, n * q / 4), side);
    std::fflush(stdout);
  }
  return status;
}
