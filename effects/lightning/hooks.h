// Private to effects/lightning: entry points for the tests, the error report and the lab, not
// part of the library's interface: the converged DBM potential of a given bolt, the boundary
// potential B at a cell, and the A* guide. Reached through CMake's effects_internal target
// (#include "lightning/hooks.h").
#pragma once

#include <cstdint>
#include <vector>

#include "effects/lightning.h"

namespace effects::lightning {

// Converged potential of the DBM problem for a given bolt (Phi = 0 on bolt, obstacles and
// outside; 1 on target) by the given solver (kCapacitance: direct while its limit allows).
// Returns the full grid, row-major.
std::vector<double> solveLaplace(int width, int height, const std::vector<uint8_t>& obstacles,
                                 const std::vector<Cell>& bolt, Cell target, Solver solver, double tolerance,
                                 int* iterations = nullptr, double* residual = nullptr);
// The same on a 3-D grid (depth > 0; depth 0: the 2-D one above); cells (z * height + y) *
// width + x.
std::vector<double> solveLaplace(int width, int height, int depth, const std::vector<uint8_t>& obstacles,
                                 const std::vector<Cell>& bolt, Cell target, Solver solver, double tolerance,
                                 int* iterations = nullptr, double* residual = nullptr);

// Seed 002 eqn 4: the boundary map's point-charge sum at a cell, sum over border ring and
// obstacle cells of 1/r (Barnes-Hut, opening angle 0.5; exact for r < 2 block sizes).
// Normalisation (division by a constant) cancels in p_i and is not applied.
double boundaryPotential(int width, int height, const std::vector<uint8_t>& obstacles, Cell c);
// In 3-D: the shell of voxels around the grid and the obstacle voxels (an octree, same angle).
double boundaryPotential(int width, int height, int depth, const std::vector<uint8_t>& obstacles, Cell c);

// A* over the 8-neighbourhood (octile heuristic) or the 4-neighbourhood (Manhattan); empty if
// unreachable. With depth > 0, over the 26-neighbourhood (3-D octile) or the 6 (Manhattan).
std::vector<Cell> astar(int width, int height, const std::vector<uint8_t>& obstacles, Cell from, Cell to,
                        int neighbourhood = 8, int depth = 0);
// The same to the nearest reachable cell of a set (goals: flags like obstacles), guided by the
// distance to the set's bounding box; empty if no cell of it is reachable.
std::vector<Cell> astarToRegion(int width, int height, const std::vector<uint8_t>& obstacles, Cell from,
                                const std::vector<uint8_t>& goals, int neighbourhood = 8, int depth = 0);

// Whether DBM's direct steps draw from bounds on Phi (on: the default) or compute Phi at every
// candidate, as before the bounded draw: the same bolt either way (docs/effects.md section 1.3),
// for the tests and the lab that show it. Process-wide; set it before growing.
void setBoundedDraw(bool on);

}  // namespace effects::lightning
