// The log of particles that left the domain (escapes.hpp).
#include "mpm/solver/escapes.hpp"

#include <cstring>

namespace mpm {

void EscapeLog::add(const ColumnStore& particles, const std::vector<std::uint32_t>& idx, double t) {
  static const char* kCopied[] = {"id", "body", "x", "v", "m", "e"};
  if (idx.empty()) return;
  if (cols_.columns().empty()) {
    for (const char* name : kCopied)
      if (const Column* c = particles.find(name)) cols_.add(c->info());
    cols_.add({kEscapeTimeColumn, ScalarType::F64, 1, "s"});
  }
  const std::size_t n0 = cols_.size();
  cols_.resize(n0 + idx.size());
  for (Column& c : cols_.columns()) {
    if (c.info().name == kEscapeTimeColumn) {
      double* to = c.as<double>() + n0;
      for (std::size_t k = 0; k < idx.size(); ++k) to[k] = t;
      continue;
    }
    const Column& from = particles.at(c.info().name);
    const std::size_t eb = c.info().element_bytes();
    for (std::size_t k = 0; k < idx.size(); ++k)
      std::memcpy(c.data() + (n0 + k) * eb, from.data() + std::size_t(idx[k]) * eb, eb);
  }
}

}  // namespace mpm
