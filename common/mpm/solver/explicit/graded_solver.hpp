#pragma once
/// The explicit solver on a graded grid (mesh-grading MPM, 004 section 3): the explicit
/// kernels with the transition shape functions of graded_grid.hpp, plus particle splitting
/// (graded_split.hpp). Instantiated in graded_solver.cpp.
#include "mpm/grid/graded_grid.hpp"
#include "mpm/solver/explicit/explicit_solver.hpp"

namespace mpm {

template <int D>
using GradedSolver = ExplicitSolver<GradedGrid<D>>;

}  // namespace mpm
