#include "mpm/core/timers.hpp"

#include <cstdio>

namespace mpm {

int KernelTimers::id(const std::string& name) {
  for (std::size_t i = 0; i < entries_.size(); ++i)
    if (entries_[i].name == name) return int(i);
  entries_.push_back({name, 0, 0});
  return int(entries_.size() - 1);
}

double KernelTimers::total() const {
  double t = 0;
  for (auto& e : entries_) t += e.seconds;
  return t;
}

std::string KernelTimers::table(double particle_steps) const {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "%-22s %10s %11s %7s %14s\n", "kernel", "calls", "seconds",
                "share", "ns/particle-step");
  out += line;
  const double tot = total();
  for (auto& e : entries_) {
    std::snprintf(line, sizeof line, "%-22s %10ld %11.3f %6.1f%% %14.1f\n", e.name.c_str(), e.calls,
                  e.seconds, tot > 0 ? 100.0 * e.seconds / tot : 0.0,
                  particle_steps > 0 ? 1e9 * e.seconds / particle_steps : 0.0);
    out += line;
  }
  std::snprintf(line, sizeof line, "%-22s %10s %11.3f %6.1f%% %14.1f\n", "total", "", tot, 100.0,
                particle_steps > 0 ? 1e9 * tot / particle_steps : 0.0);
  out += line;
  return out;
}

}  // namespace mpm
