#pragma once
/// One value of a particle column of any scalar type, as a double.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "mpm/core/columns.hpp"

namespace mpm {

/// Element i, component k of a column as a double.
inline double column_value(const Column& c, std::size_t i, int k) {
  const std::size_t at = i * std::size_t(c.info().components) + std::size_t(k);
  const std::byte* d = c.data();
  switch (c.info().type) {
    case ScalarType::F64:
      return reinterpret_cast<const double*>(d)[at];
    case ScalarType::F32:
      return reinterpret_cast<const float*>(d)[at];
    case ScalarType::U8:
      return double(reinterpret_cast<const std::uint8_t*>(d)[at]);
    case ScalarType::U32:
      return double(reinterpret_cast<const std::uint32_t*>(d)[at]);
    case ScalarType::I32:
      return double(reinterpret_cast<const std::int32_t*>(d)[at]);
    case ScalarType::U64:
      return double(reinterpret_cast<const std::uint64_t*>(d)[at]);
  }
  return NAN;
}

}  // namespace mpm
