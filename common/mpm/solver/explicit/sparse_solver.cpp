// Instantiations of the explicit solver on the sparse grid.
#include "mpm/solver/explicit/sparse_solver.hpp"

#include "mpm/solver/explicit/explicit_solver_impl.hpp"

namespace mpm {

static_assert(Grid<SparseGrid<2>> && Grid<SparseGrid<3>>);
template class ExplicitSolver<SparseGrid<2>>;
template class ExplicitSolver<SparseGrid<3>>;

}  // namespace mpm
