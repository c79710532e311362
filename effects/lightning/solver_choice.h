// The one rule for which Laplace solver takes a DBM problem (growth.cpp's every step, a deep
// field's rebuilt stage, the public solveLaplace): capacitance.h's direct solver when asked for,
// when the grid fits it and when its fixed cells (obstacles, bolt, target), with the cells still
// to come, stay within its direct limit (maxFixed); else the iterative solver of the grid's
// dimension (laplace.h, laplace3.h). A growing bolt expects as many cells again as it has fixed
// (past the limit the solver hands over to MGPCG mid-growth); a single solve expects none.
#pragma once

#include <cstddef>
#include <memory>

#include "laplace.h"

namespace effects::lightning::detail {

// parallel: where the iterative solver's fine level may split its loops (null: this thread).
std::unique_ptr<Potential> potentialFor(int width, int height, int depth, Solver solver, size_t fixedCells,
                                        size_t cellsToCome, Parallel* parallel = nullptr);

}  // namespace effects::lightning::detail
