#include "mpm/core/error.hpp"

namespace mpm {

std::string where(const std::string& file, int line, const std::string& key) {
  std::string s = file;
  if (line > 0) s += (s.empty() ? "line " : ":") + std::to_string(line);
  if (!key.empty()) s += (s.empty() ? "" : ": ") + key;
  return s;
}

}  // namespace mpm
