#pragma once
/// The explicit solver on the sparse grid (nodes only around the occupied cells): the kernels
/// of explicit_solver_impl.hpp unchanged. Instantiated in sparse_solver.cpp.
#include "mpm/explicit_solver.hpp"
#include "mpm/sparse_grid.hpp"

namespace mpm {

template <int D>
using SparseSolver = ExplicitSolver<SparseGrid<D>>;

}  // namespace mpm
