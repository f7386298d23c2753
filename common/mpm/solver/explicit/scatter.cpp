// The scatter strategies' names.
#include "mpm/solver/explicit/scatter.hpp"

#include <utility>

namespace mpm {

namespace {
constexpr std::pair<ScatterStrategy, const char*> kStrategyNames[] = {
    {ScatterStrategy::Colored, "colored"},
    {ScatterStrategy::LRSlabs, "lr-slabs"},
    {ScatterStrategy::ArrayExpansion, "array-expansion"},
    {ScatterStrategy::Patch, "patch"},
};
}  // namespace

std::string to_string(ScatterStrategy s) {
  for (const auto& [strategy, name] : kStrategyNames)
    if (strategy == s) return name;
  return "?";
}

ScatterStrategy parse_strategy(const std::string& name, const std::string& where) {
  for (const auto& [strategy, strategy_name] : kStrategyNames)
    if (name == strategy_name) return strategy;
  throw InputError(where, "unknown strategy '" + name +
                              "' (expected colored, lr-slabs, array-expansion or patch)");
}

}  // namespace mpm
