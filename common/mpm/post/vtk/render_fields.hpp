#pragma once
/// The field a picture is coloured by, evaluated on every particle (internal to mpm_vtk).
#include <string>
#include <vector>

#include "mpm/stream/stream.hpp"

namespace mpm::vtk_internal {

/// A field evaluated on every particle.
struct FieldValues {
  std::string label;  ///< "pressure", "v_x", "|v|", ...
  std::string unit;   ///< "Pa", "" when none or dimensionless
  std::vector<float> values;
};

/// Evaluates `field` (a column or "pressure", "von_mises", "speed"; component -1: the
/// magnitude, von Mises for tensors) on every particle. Throws InputError for an unknown field
/// (listing the available ones) or component.
FieldValues evaluate_field(const Frame& frame, const std::string& field, int component);

}  // namespace mpm::vtk_internal
