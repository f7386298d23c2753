// Instantiations of the explicit solver on the uniform window grid. The solver itself, with
// its time step at the top, is in explicit_solver_impl.hpp.
#include "mpm/solver/explicit/explicit_solver_impl.hpp"

namespace mpm {

InstabilityError::InstabilityError(long step_, double time_, long particle_,
                                   const std::string& cause_)
    : std::runtime_error("unstable at step " + std::to_string(step_) + " (t = " +
                         [&] {
                           char b[32];
                           std::snprintf(b, sizeof b, "%.6g s", time_);
                           return std::string(b);
                         }() +
                         (particle_ >= 0 ? "), particle " + std::to_string(particle_) : ")") +
                         ": " + cause_),
      step(step_),
      time(time_),
      particle(particle_),
      cause(cause_) {}

std::string to_string(ScatterStrategy s) {
  switch (s) {
    case ScatterStrategy::Colored:
      return "colored";
    case ScatterStrategy::LRSlabs:
      return "lr-slabs";
    case ScatterStrategy::ArrayExpansion:
      return "array-expansion";
    case ScatterStrategy::Patch:
      return "patch";
  }
  return "?";
}

ScatterStrategy parse_strategy(const std::string& name, const std::string& where) {
  for (auto s : {ScatterStrategy::Colored, ScatterStrategy::LRSlabs,
                 ScatterStrategy::ArrayExpansion, ScatterStrategy::Patch})
    if (to_string(s) == name) return s;
  throw InputError(where, "unknown strategy '" + name +
                              "' (expected colored, lr-slabs, array-expansion or patch)");
}

template class ExplicitSolver<UniformGrid<2>>;
template class ExplicitSolver<UniformGrid<3>>;

}  // namespace mpm
