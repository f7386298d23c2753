#pragma once
/// Small fixed vectors for the trilinear kernels (uniform and sparse 3D cells): the 8 corners
/// of a cell, or the 4 edges along an axis, one lane each, as vectors of GCC's (and clang's)
/// vector extension, which the compiler maps onto the target's registers (one AVX-512
/// register, two AVX2 ones, ...). Written as plain doubles, such products were built one at a
/// time and packed into vectors, and the packing cost more than the arithmetic.
namespace mpm::lanes {

using V8 = double __attribute__((vector_size(64)));
using V4 = double __attribute__((vector_size(32)));
using I8 = long long __attribute__((vector_size(64)));
using I4 = long long __attribute__((vector_size(32)));

/// lo in the lanes whose index has `bit` clear, hi where it is set.
inline V8 spread8(double lo, double hi, long long bit) {
  const I8 lane = {0, 1, 2, 3, 4, 5, 6, 7};
  return (lane & bit) != 0 ? V8{} + hi : V8{} + lo;
}
inline V4 spread4(double lo, double hi, long long bit) {
  const I4 lane = {0, 1, 2, 3};
  return (lane & bit) != 0 ? V4{} + hi : V4{} + lo;
}

/// The trilinear weights of the corners c = bx + 2 by + 4 bz at local coordinates (x, y, z) in
/// [0, 1)^3: shape_values' products ((1 w_x) w_y) w_z, lane c.
inline V8 corner_weights(double x, double y, double z) {
  return spread8(1.0 - x, x, 1) * spread8(1.0 - y, y, 2) * spread8(1.0 - z, z, 4);
}

}  // namespace mpm::lanes
