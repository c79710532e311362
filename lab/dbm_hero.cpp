// dbm_hero: exact DBM hero bolts at large grids (docs/lightning-hero.md), in one run per grid
// side (top centre to bottom centre, eta 2, 8 neighbours, seed 1):
//   1. the bolt by the direct solver (capacitance, the default) with the bounded draw (2-D) on
//      one thread and on two (Params::parallel), by the same solver computing Phi at every
//      candidate (the solver before the bounded draw) on two threads, and with --mgpcg by
//      MGPCG at the default tolerance 1e-6 on two: seconds, cells, steps (how many direct), at
//      how many candidates the bounded draw computed Phi, and a hash of the cells in growth
//      order. The same hash means the same bolt, cell for cell; the program exits 1 when one
//      differs.
//   2. exactness at sampled steps (1/4, 1/2, 3/4 of the bolt): the step solved by each solver
//      as growth solves it against MGPCG from scratch to 1e-12: the candidates' largest error
//      relative to their largest potential P, and the total variation distance between the
//      two candidate distributions Phi^eta / sum.
// Usage: dbm_hero [--mgpcg] [side ...]   (default 256 512 1024).
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "effects/lightning.h"
#include "lightning/deep_field.h"
#include "lightning/hooks.h"
#include "lightning/laplace.h"
#include "lightning/solver_choice.h"

namespace lt = effects::lightning;
namespace ld = effects::lightning::detail;

namespace {

constexpr double kEta = 2.0;
constexpr double kTolerance = 1e-6;

bool volume = false;  // --volume: sides are cubes' (26 neighbours), the start and target the
                      // centres of the top and bottom faces

lt::Cell targetOf(int side) { return volume ? lt::Cell{side / 2, side - 1, side / 2} : lt::Cell{side / 2, side - 1}; }

lt::Params layout(int side, lt::Solver solver) {
  lt::Params p;
  p.width = p.height = side;
  p.depth = volume ? side : 0;
  p.start = volume ? lt::Cell{side / 2, 0, side / 2} : lt::Cell{side / 2, 0};
  p.targets = {targetOf(side)};
  p.method = lt::Method::kDbm;
  p.solver = solver;
  p.eta = kEta;
  p.tolerance = kTolerance;
  p.neighbourhood = volume ? 26 : 8;
  p.seed = 1;
  return p;
}

uint64_t hashOf(const lt::Bolt& b) {  // FNV-1a over the cells in growth order
  uint64_t h = 1469598103934665603ull;
  for (const lt::Node& n : b.nodes)
    for (int v : {n.cell.x, n.cell.y, n.cell.z}) h = (h ^ uint64_t(uint32_t(v))) * 1099511628211ull;
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

// The free 8-neighbours (26 in a volume) of the first n cells: the candidates of step n.
std::vector<lt::Cell> candidates(const lt::Bolt& b, size_t n, int side) {
  const int depth = volume ? side : 1;
  auto index = [&](lt::Cell c) { return (size_t(c.z) * size_t(side) + size_t(c.y)) * size_t(side) + size_t(c.x); };
  std::vector<uint8_t> bolt(size_t(side) * size_t(side) * size_t(depth), 0), seen(bolt.size(), 0);
  for (size_t i = 0; i < n; ++i) bolt[index(b.nodes[i].cell)] = 1;
  std::vector<lt::Cell> out;
  const lt::Cell target = targetOf(side);
  const int reach = volume ? 1 : 0;
  for (size_t i = 0; i < n; ++i)
    for (int dz = -reach; dz <= reach; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const lt::Cell c{b.nodes[i].cell.x + dx, b.nodes[i].cell.y + dy, b.nodes[i].cell.z + dz};
          if (c.x < 0 || c.y < 0 || c.z < 0 || c.x >= side || c.y >= side || c.z >= depth) continue;
          const size_t k = index(c);
          if (bolt[k] || seen[k] || c == target) continue;
          seen[k] = 1;
          out.push_back(c);
        }
  return out;
}

std::unique_ptr<ld::DeepField> problem(const lt::Bolt& b, size_t n, int side, lt::Solver solver) {
  const int depth = volume ? side : 0;
  auto f = std::make_unique<ld::DeepField>(ld::potentialFor(side, side, depth, solver, n + 1, 0), side, side, depth);
  for (size_t i = 0; i < n; ++i) f->fix(b.nodes[i].cell, 0.0);
  f->fix(targetOf(side), 1.0);
  return f;
}

// The candidates' largest error relative to their largest potential P, and the total variation
// distance between the two distributions Phi^eta / sum.
struct Against {
  double P = 0, error = 0, tv = 0;
};
Against compare(const std::vector<double>& logPhi, const std::vector<double>& refLogPhi) {
  Against a;
  double sum = 0, refSum = 0;
  for (size_t i = 0; i < refLogPhi.size(); ++i) a.P = std::max(a.P, std::exp(refLogPhi[i]));
  for (size_t i = 0; i < refLogPhi.size(); ++i) {
    a.error = std::max(a.error, std::fabs(std::exp(logPhi[i]) - std::exp(refLogPhi[i])) / a.P);
    sum += std::exp(kEta * logPhi[i]);
    refSum += std::exp(kEta * refLogPhi[i]);
  }
  for (size_t i = 0; i < refLogPhi.size(); ++i)
    a.tv += 0.5 * std::fabs(std::exp(kEta * logPhi[i]) / sum - std::exp(kEta * refLogPhi[i]) / refSum);
  return a;
}

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// Step n (its bolt: the first n cells) as growth solves it, by each solver, against MGPCG from
// scratch to 1e-12 (the reference neither shares code with the direct solver nor stops where
// growth's MGPCG stops).
void sampledStep(const lt::Bolt& b, size_t n, int side) {
  const std::vector<lt::Cell> probes = candidates(b, n, side);
  std::vector<double> direct, warm, ref;
  // The direct solver: the cells fixed one by one as growth fixes them, then one solve.
  auto cap = problem(b, n, side, lt::Solver::kCapacitance);
  auto t0 = std::chrono::steady_clock::now();
  cap->solve(lt::Solver::kCapacitance, kTolerance, probes, direct);
  const double capMs = msSince(t0);
  // MGPCG: the bolt up to cell n - 1 solved to the tolerance, cell n fixed, a warm solve.
  auto mg = problem(b, n - 1, side, lt::Solver::kMgpcg);
  mg->solve(lt::Solver::kMgpcg, kTolerance, candidates(b, n - 1, side), warm);
  mg->fix(b.nodes[n - 1].cell, 0.0);
  t0 = std::chrono::steady_clock::now();
  const int its = mg->solve(lt::Solver::kMgpcg, kTolerance, probes, warm);
  const double mgMs = msSince(t0);
  problem(b, n, side, lt::Solver::kMgpcg)->solve(lt::Solver::kMgpcg, 1e-12, probes, ref);
  const Against d = compare(direct, ref), m = compare(warm, ref);
  std::printf(
      "  step %6zu: %5zu candidates, P %.3e | direct %s(from scratch) %6.1f ms, error/P %.2e, TV %.2e "
      "| MGPCG %d V-cycles %6.1f ms, error/P %.2e, TV %.2e\n",
      n, probes.size(), d.P, cap->direct() ? "" : "(HANDED OVER)", capMs, d.error, d.tv, its, mgMs, m.error, m.tv);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> sides;
  bool withMgpcg = false;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--mgpcg")
      withMgpcg = true;
    else if (std::string(argv[i]) == "--volume")
      volume = true;
    else
      sides.push_back(std::atoi(argv[i]));
  }
  if (sides.empty()) sides = volume ? std::vector<int>{64, 96, 128} : std::vector<int>{256, 512, 1024};
  int status = 0;
  effects::ThreadPool pool(1);  // the caller and one worker: this machine's two cores
  std::printf(
      "exact DBM, top centre to bottom centre, eta %.0f, %d neighbours, seed 1; the direct (capacitance) "
      "solver%s%s\n",
      kEta, volume ? 26 : 8,
      volume ? " (every candidate: 3-D has no bounded draw)" : " with the bounded draw against the same solver weighing every candidate",
      withMgpcg ? ", and MGPCG at 1e-6" : "");
  for (int side : sides) {
    const Run one = grow(side, lt::Solver::kCapacitance);
    const Run two = grow(side, lt::Solver::kCapacitance, &pool);
    lt::setBoundedDraw(false);
    const Run every = grow(side, lt::Solver::kCapacitance, &pool);
    lt::setBoundedDraw(true);
    Run mg;
    if (withMgpcg) mg = grow(side, lt::Solver::kMgpcg, &pool);
    const effects::Stats& s = two.bolt.stats;
    const double steps = s.counters.at("steps");
    std::vector<lt::Cell> cells;
    for (const lt::Node& n : two.bolt.nodes) cells.push_back(n.cell);
    std::printf("%4d^%d: %6zu cells  %6.0f steps (%.0f direct)  D %.3f  hash %016" PRIx64 "\n", side, volume ? 3 : 2,
                two.bolt.nodes.size(), steps, s.counters.at("directSteps"),
                volume ? lt::fractalDimension(cells, side, side, side) : lt::fractalDimension(cells, side, side),
                hashOf(two.bolt));
    // 3-D computes every candidate (dbm.cpp): the two direct runs are then the same solver.
    const bool bounded = s.counters.count("candidatesWeighed") > 0;
    const char* direct = bounded ? "bounded draw" : "direct";
    std::printf("        %s, 1 thread:  %8.2f s\n", direct, one.seconds);
    std::printf("        %s, 2 threads: %8.2f s  (1 thread / 2 threads %.2fx", direct, two.seconds, one.seconds / two.seconds);
    if (bounded)
      std::printf("; Phi at %.0f of %.0f candidates, %.1f %%", s.counters.at("candidatesWeighed"),
                  s.counters.at("candidatesOffered"),
                  100 * s.counters.at("candidatesWeighed") / s.counters.at("candidatesOffered"));
    std::printf(")\n");
    if (bounded)
      std::printf("        every candidate, 2 threads: %8.2f s  (every candidate / bounded draw %.2fx)\n", every.seconds,
                  every.seconds / two.seconds);
    if (withMgpcg)
      std::printf("        MGPCG, 2 threads:  %8.2f s  (%.2f V-cycles a step; MGPCG / %s %.1fx)\n", mg.seconds,
                  mg.bolt.stats.counters.at("solverIterations") / mg.bolt.stats.counters.at("steps"), direct,
                  mg.seconds / two.seconds);
    for (const Run* r : {&one, &every, static_cast<const Run*>(&mg)}) {
      if (r == &mg && !withMgpcg) continue;
      if (hashOf(r->bolt) == hashOf(two.bolt)) continue;
      std::printf("        A DIFFERENT BOLT: %s, hash %016" PRIx64 "\n",
                  r == &one ? "bounded draw on 1 thread" : r == &every ? "every candidate" : "MGPCG", hashOf(r->bolt));
      status = 1;
    }
    const size_t n = two.bolt.nodes.size();
    for (size_t q = 1; q <= 3; ++q) sampledStep(two.bolt, std::max<size_t>(2, n * q / 4), side);
    std::fflush(stdout);
  }
  return status;
}
