// The solver core's messages; the core itself is a template (core.hpp).
#include "mpm/solver/core.hpp"

#include <cstdio>

namespace mpm {

InstabilityError::InstabilityError(long step_, double time_, long particle_,
                                   const std::string& cause_, bool left_domain_)
    : std::runtime_error((left_domain_ ? "stopped at step " : "unstable at step ") +
                         std::to_string(step_) + " (t = " +
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
      cause(cause_),
      left_domain(left_domain_) {}

std::string energy_growth_message(double growth, double scale, double limit, const char* remedy) {
  char msg[256];
  std::snprintf(msg, sizeof msg,
                "total energy grew by %.3g J, %.1f%% of its scale %.3g J (limit "
                "solver.energy_growth_limit = %g): %s",
                growth, 100.0 * growth / scale, scale, limit, remedy);
  return msg;
}

std::string exit_message(const double* x, int dim) {
  char where[160];
  std::snprintf(where, sizeof where, "left the domain at (%.4g, %.4g, %.4g) m", x[0], x[1],
                dim == 3 ? x[dim - 1] : 0.0);
  return std::string(where) +
         " (solver.on_exit = \"stop\"; this is not an instability: enlarge grid.domain, or set "
         "solver.on_exit = \"remove\" to let such particles go)";
}

}  // namespace mpm
