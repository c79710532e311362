#include "solver_choice.h"
#include "hooks.h"

#include <algorithm>

#include "capacitance.h"
#include "grid.h"
#include "laplace3.h"

namespace effects::lightning::detail {

std::unique_ptr<Potential> potentialFor(int width, int height, int depth, Solver solver, size_t fixedCells,
                                        size_t cellsToCome, Parallel* parallel) {
  if (solver == Solver::kCapacitance && Capacitance::fits(width, height, depth) &&
      fixedCells + cellsToCome <= Capacitance::maxFixed(width, height, depth))
    return std::make_unique<Capacitance>(width, height, depth, parallel);
  if (depth > 0) return std::make_unique<Laplace3>(width, height, depth, parallel);
  return std::make_unique<Laplace>(width, height, parallel);
}

}  // namespace effects::lightning::detail

namespace effects::lightning {

std::vector<double> solveLaplace(int width, int height, int depth, const std::vector<uint8_t>& obstacles,
                                 const std::vector<Cell>& bolt, Cell target, Solver solver, double tolerance,
                                 int* iterations, double* residual) {
  size_t fixedCells = bolt.size() + 1;
  for (uint8_t o : obstacles) fixedCells += o != 0;
  std::unique_ptr<detail::Potential> lap = detail::potentialFor(width, height, depth, solver, fixedCells, 0);
  const detail::Grid g{width, height, &obstacles, std::max(depth, 1)};
  for (size_t i = 0; i < g.cells(); ++i)
    if (!obstacles.empty() && obstacles[i]) lap->fix(g.cellAt(i), 0.0);
  for (const Cell& c : bolt) lap->fix(c, 0.0);
  lap->fix(target, 1.0);
  int it = lap->solve(solver, tolerance);
  if (iterations) *iterations = it;
  if (residual) *residual = lap->residual();
  std::vector<double> out(g.cells());
  for (size_t i = 0; i < out.size(); ++i) out[i] = lap->phi(g.cellAt(i));
  return out;
}

std::vector<double> solveLaplace(int width, int height, const std::vector<uint8_t>& obstacles,
                                 const std::vector<Cell>& bolt, Cell target, Solver solver, double tolerance,
                                 int* iterations, double* residual) {
  return solveLaplace(width, height, 0, obstacles, bolt, target, solver, tolerance, iterations, residual);
}

}  // namespace effects::lightning
