// Command-line values of mpm-post's subcommands.
#include "mpm/post/arguments.hpp"

#include <cstdlib>
#include <stdexcept>
#include <vector>

#include "mpm/core/error.hpp"

namespace mpm {

double option_quantity(const std::string& text, const Dimension& dim, const std::string& option) {
  try {
    std::size_t used = 0;
    try {
      const double v = std::stod(text, &used);
      if (used == text.size()) return v;
    } catch (const std::logic_error&) {
    }
    const Quantity q = parse_quantity(text);
    if (!(q.dim == dim)) throw std::invalid_argument("expected " + describe(dim));
    return q.value;
  } catch (const std::invalid_argument& e) {
    throw InputError(option, std::string(e.what()) + " in '" + text + "'");
  }
}

int option_axis(const std::string& text, const std::string& option) {
  if (text != "x" && text != "y" && text != "z")
    throw InputError(option, "expected x, y or z, got '" + text + "'");
  return text[0] - 'x';
}

Vec3 option_point(const std::string& text, const std::string& option) {
  std::vector<Quantity> qs;
  try {
    qs = parse_vector(text);
  } catch (const std::invalid_argument& e) {
    throw InputError(option, std::string(e.what()) + " in '" + text + "'");
  }
  if (qs.size() < 2 || qs.size() > 3)
    throw InputError(option, "expected 2 or 3 components, e.g. \"0 0 0 mm\", got '" + text + "'");
  Vec3 x = Vec3::Zero();
  for (std::size_t a = 0; a < qs.size(); ++a) {
    if (!(qs[a].dim == dim::length) && !(qs[a].dim == dim::none))
      throw InputError(option, "expected lengths, got '" + text + "'");
    x[a] = qs[a].value;
  }
  return x;
}

long option_frame(const std::string& text) {
  if (text == "last") return -1;
  char* end = nullptr;
  const long want = std::strtol(text.c_str(), &end, 10);
  if (!end || *end || want < 0)
    throw InputError("--frame", "expected a frame index or 'last', got '" + text + "'");
  return want;
}

}  // namespace mpm
