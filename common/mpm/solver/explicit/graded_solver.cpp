// Instantiations of the explicit solver on the graded grid (mesh-grading MPM, 004 section 3),
// with its particle-splitting kernel.
#include "mpm/grid/graded_grid.hpp"
#include "mpm/solver/explicit/explicit_solver_impl.hpp"
#include "mpm/solver/explicit/graded_split.hpp"

namespace mpm {

template class ExplicitSolver<GradedGrid<2>>;
template class ExplicitSolver<GradedGrid<3>>;

}  // namespace mpm
