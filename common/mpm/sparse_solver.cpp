// Instantiations of the explicit solver on the sparse grid.
#include "mpm/explicit_solver_impl.hpp"
#include "mpm/sparse_solver.hpp"

namespace mpm {

template class ExplicitSolver<SparseGrid<2>>;
template class ExplicitSolver<SparseGrid<3>>;

}  // namespace mpm
