#pragma once
/// The particles that leave the domain (solver.on_exit = "remove"): their state when they
/// left, kept as columns until the run writes them to its stream as an ESCP record
/// (docs/format.md), so that the mass and momentum they take with them stay on the books.
#include <cstdint>
#include <string>
#include <vector>

#include "mpm/core/columns.hpp"

namespace mpm {

/// Name of the column of the time a particle left the domain (f64, s): the end of the step
/// in which it crossed the boundary.
inline const std::string kEscapeTimeColumn = "t_exit";

/// Escaped particles as columns: the particle columns id, body, x, v, m and e copied as they
/// were (same types and units), and t_exit.
class EscapeLog {
 public:
  /// Appends the particles `idx` of `particles` (indices into its columns), which left the
  /// domain by time t (s).
  void add(const ColumnStore& particles, const std::vector<std::uint32_t>& idx, double t);
  /// The particles logged since the last clear().
  ColumnStore& columns() { return cols_; }
  std::size_t size() const { return cols_.size(); }
  /// Empties the log (once written); the column table stays.
  void clear() { cols_.resize(0); }

 private:
  ColumnStore cols_;
};

}  // namespace mpm
