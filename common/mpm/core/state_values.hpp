#pragma once
/// Named scalars of a solver's state between two steps (time, step, the energy balance, ...):
/// what a checkpoint holds besides the particle columns. Values are f64, kept exactly;
/// counts (steps, particle ids) are below 2^53, so a double holds them exactly too.
#include <string>
#include <utility>
#include <vector>

#include "mpm/core/error.hpp"

namespace mpm {

class StateValues {
 public:
  /// Sets `name` (adds it when absent, keeping the order of first insertion).
  void set(const std::string& name, double value) {
    for (auto& [n, v] : items_)
      if (n == name) {
        v = value;
        return;
      }
    items_.emplace_back(name, value);
  }
  /// The value of `name`; InputError ("checkpoint: ... lacks 'name'") when absent.
  double get(const std::string& name) const {
    for (const auto& [n, v] : items_)
      if (n == name) return v;
    throw InputError("checkpoint", "the record lacks the state value '" + name +
                                       "' (written by another version of mpm-run?)");
  }
  bool has(const std::string& name) const {
    for (const auto& item : items_)
      if (item.first == name) return true;
    return false;
  }
  /// Every value, in the order of first insertion.
  const std::vector<std::pair<std::string, double>>& items() const { return items_; }

 private:
  std::vector<std::pair<std::string, double>> items_;
};

}  // namespace mpm
