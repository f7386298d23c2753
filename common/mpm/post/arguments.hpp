#pragma once
/// Command-line values of mpm-post's subcommands turned into typed ones. Each throws
/// InputError naming the option when the text does not parse.
#include <string>

#include "mpm/core/types.hpp"
#include "mpm/core/units.hpp"

namespace mpm {

/// A quantity of dimension `dim`: "16.2 mm", or a plain number in SI units (as in scene files).
double option_quantity(const std::string& text, const Dimension& dim, const std::string& option);

/// An axis, "x", "y" or "z", as 0, 1, 2.
int option_axis(const std::string& text, const std::string& option);

/// A point of 2 or 3 lengths, e.g. "0 0 0 mm" (plain numbers in m), padded with z = 0.
Vec3 option_point(const std::string& text, const std::string& option);

/// A frame index (0 = first) of --frame, or -1 for "last".
long option_frame(const std::string& text);

}  // namespace mpm
