#pragma once
/// Columns of a frame as the VTK writers and the renderer read them (internal to mpm_vtk).
#include <array>
#include <cstdint>
#include <stdexcept>

#include "mpm/core/types.hpp"
#include "mpm/stream/stream.hpp"

namespace mpm::vtk_internal {

/// Calls f(T{}) with the C++ type of a scalar type.
template <class F>
decltype(auto) visit_scalar(ScalarType t, F&& f) {
  switch (t) {
    case ScalarType::F64:
      return f(double{});
    case ScalarType::F32:
      return f(float{});
    case ScalarType::U8:
      return f(std::uint8_t{});
    case ScalarType::U32:
      return f(std::uint32_t{});
    case ScalarType::I32:
      return f(std::int32_t{});
    case ScalarType::U64:
      return f(std::uint64_t{});
  }
  throw std::logic_error("unknown scalar type");
}

/// Whether a scalar type is f64 or f32.
bool is_floating(ScalarType t);

/// A 6-component floating column is a symmetric tensor in Voigt order (types.hpp: Sym).
bool is_voigt(const ColumnInfo& info);

/// Element i, component c of a column as a double.
template <class T>
double value_at(const Column& c, std::size_t i, int k) {
  return double(reinterpret_cast<const T*>(c.data())[i * c.info().components + k]);
}

/// A column's data as a flat array of T (checked by type, not by element size).
template <class T>
const T* raw(const Column& c) {
  return reinterpret_cast<const T*>(c.data());
}

/// Voigt (xx, yy, zz, yz, xz, xy) of element i of a floating 6-component column.
Sym voigt_at(const Column& c, std::size_t i);

/// The magnitude of element i of a floating column (a speed of the velocity column "v").
double norm_at(const Column& c, std::size_t i);

/// Position of particle i padded to 3D.
std::array<double, 3> position(const Column& x, std::size_t i);

/// The position column of a frame of dimension `dim` (2 or 3); throws InputError naming
/// `where` when the dimension or the column does not fit.
const Column& positions(const Frame& frame, int dim, const char* where);

}  // namespace mpm::vtk_internal
