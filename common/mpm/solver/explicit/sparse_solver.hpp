#pragma once
/// The explicit solver on the sparse grid (nodes only around the occupied cells): the explicit
/// kernels unchanged. Instantiated in sparse_solver.cpp.
#include "mpm/grid/sparse_grid.hpp"
#include "mpm/solver/explicit/explicit_solver.hpp"

namespace mpm {

template <int D>
using SparseSolver = ExplicitSolver<SparseGrid<D>>;

}  // namespace mpm
