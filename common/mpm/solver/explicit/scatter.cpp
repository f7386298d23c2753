// The scatter strategies' names.
#include "mpm/solver/explicit/scatter.hpp"

namespace mpm {

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

}  // namespace mpm
