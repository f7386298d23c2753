// Instantiations of the explicit solver on the graded grid (mesh-grading MPM, 004 section 3),
// with its particle-splitting kernel.
#include "mpm/explicit_solver_impl.hpp"
#include "mpm/graded_grid.hpp"
#include "mpm/graded_split.hpp"

namespace mpm {

template class ExplicitSolver<GradedGrid<2>>;
template class ExplicitSolver<GradedGrid<3>>;

}  // namespace mpm
