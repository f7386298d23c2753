// Instantiations of the explicit solver on the uniform window grid. The solver itself, with
// its time step at the top, is in explicit_solver_impl.hpp.
#include "mpm/solver/explicit/explicit_solver_impl.hpp"

namespace mpm {

template class ExplicitSolver<UniformGrid<2>>;
template class ExplicitSolver<UniformGrid<3>>;

}  // namespace mpm
