// Columns of a frame as the VTK writers and the renderer read them.
#include "mpm/post/vtk/frame_columns.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "mpm/core/error.hpp"

namespace mpm::vtk_internal {

bool is_floating(ScalarType t) {
  return t == ScalarType::F64 || t == ScalarType::F32;
}

bool is_voigt(const ColumnInfo& info) {
  return info.components == 6 && is_floating(info.type);
}

Sym voigt_at(const Column& c, std::size_t i) {
  Sym s;
  if (c.info().type == ScalarType::F64) {
    const double* p = raw<double>(c) + 6 * i;
    for (int k = 0; k < 6; ++k) s[k] = p[k];
  } else {
    const float* p = raw<float>(c) + 6 * i;
    for (int k = 0; k < 6; ++k) s[k] = p[k];
  }
  return s;
}

double norm_at(const Column& c, std::size_t i) {
  const int nc = c.info().components;
  const bool f64 = c.info().type == ScalarType::F64;
  double s = 0;
  for (int k = 0; k < nc; ++k) {
    const double x = f64 ? value_at<double>(c, i, k) : value_at<float>(c, i, k);
    s += x * x;
  }
  return std::sqrt(s);
}

std::array<double, 3> position(const Column& x, std::size_t i) {
  std::array<double, 3> p{0, 0, 0};
  const int nc = std::min(x.info().components, 3);
  for (int k = 0; k < nc; ++k)
    p[k] = x.info().type == ScalarType::F64 ? value_at<double>(x, i, k) : value_at<float>(x, i, k);
  return p;
}

const Column& positions(const Frame& frame, int dim, const char* where) {
  if (dim != 2 && dim != 3)
    throw InputError(where, "dimension must be 2 or 3, not " + std::to_string(dim));
  const Column* x = frame.columns.find("x");
  if (!x) throw InputError(where, "the frame has no position column 'x'");
  if (x->info().components != dim || !is_floating(x->info().type))
    throw InputError(where, "column 'x' has " + std::to_string(x->info().components) + " x " +
                                scalar_name(x->info().type) + ", expected " + std::to_string(dim) +
                                " x f64 for a " + std::to_string(dim) + "D frame");
  return *x;
}

}  // namespace mpm::vtk_internal
