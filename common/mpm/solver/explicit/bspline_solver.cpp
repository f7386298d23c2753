// Instantiations of the explicit solver on the quadratic B-spline grid (grid.shape = "bspline").
#include "mpm/grid/bspline_grid.hpp"
#include "mpm/solver/explicit/explicit_solver_impl.hpp"

namespace mpm {

template class ExplicitSolver<BsplineGrid<2>>;
template class ExplicitSolver<BsplineGrid<3>>;

}  // namespace mpm
