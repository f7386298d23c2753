// Instantiations of the explicit solver on the graded grid (mesh-grading MPM, 004 section 3),
// with its particle-splitting kernel (graded_split.hpp).
#include "mpm/solver/explicit/graded_solver.hpp"

#include "mpm/solver/explicit/explicit_solver_impl.hpp"

namespace mpm {

static_assert(Grid<GradedGrid<2>> && Grid<GradedGrid<3>>);
template class ExplicitSolver<GradedGrid<2>>;
template class ExplicitSolver<GradedGrid<3>>;

}  // namespace mpm
