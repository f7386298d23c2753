#pragma once
/// Basic numeric types shared by every part of the toolchain. SI units throughout.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>

namespace mpm {

template <int D>
using Vec = Eigen::Matrix<double, D, 1>;  ///< spatial vector in D dimensions
template <int D>
using Mat = Eigen::Matrix<double, D, D>;  ///< D x D tensor
template <int D>
using IVec = Eigen::Matrix<int, D, 1>;  ///< integer grid index in D dimensions
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

/// Symmetric second-order tensor in Voigt order xx, yy, zz, yz, xz, xy (no factor 2 on shear).
/// Stress is stored this way in both 2D and 3D (plane strain keeps sigma_zz).
using Sym = Eigen::Matrix<double, 6, 1>;

/// Full 3x3 matrix of a Voigt tensor.
inline Mat3 to_matrix(const Sym& s) {
  Mat3 m;
  m << s[0], s[5], s[4], s[5], s[1], s[3], s[4], s[3], s[2];
  return m;
}
/// Voigt form of the symmetric part of a 3x3 matrix.
inline Sym to_voigt(const Mat3& m) {
  Sym s;
  s << m(0, 0), m(1, 1), m(2, 2), 0.5 * (m(1, 2) + m(2, 1)), 0.5 * (m(0, 2) + m(2, 0)),
      0.5 * (m(0, 1) + m(1, 0));
  return s;
}
/// Trace of a Voigt tensor.
inline double trace(const Sym& s) {
  return s[0] + s[1] + s[2];
}
/// Deviatoric part of a Voigt tensor.
inline Sym deviator(const Sym& s) {
  Sym d = s;
  const double m = trace(s) / 3.0;
  d[0] -= m;
  d[1] -= m;
  d[2] -= m;
  return d;
}
/// Double contraction a:b of two symmetric tensors in Voigt order.
inline double ddot(const Sym& a, const Sym& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + 2.0 * (a[3] * b[3] + a[4] * b[4] + a[5] * b[5]);
}
/// Largest principal value of a symmetric tensor: its mean plus that of its deviator d,
/// 2 sqrt(J2 / 3) cos(theta) with cos(3 theta) = (3 sqrt(3) / 2) J3 / J2^(3/2), theta in
/// [0, pi / 3] (J2 = d:d / 2, J3 = det d; the closed form of the cubic's largest root).
inline double largest_eigenvalue(const Sym& s) {
  const Sym d = deviator(s);
  const double J2 = 0.5 * ddot(d, d);
  const double mean = trace(s) / 3.0;
  if (!(J2 > 0)) return mean;
  const double J3 = d[0] * (d[1] * d[2] - d[3] * d[3]) - d[5] * (d[5] * d[2] - d[3] * d[4]) +
                    d[4] * (d[5] * d[3] - d[1] * d[4]);
  const double c = std::clamp(1.5 * std::sqrt(3.0) * J3 / (J2 * std::sqrt(J2)), -1.0, 1.0);
  return mean + 2.0 * std::sqrt(J2 / 3.0) * std::cos(std::acos(c) / 3.0);
}
/// Von Mises equivalent of a stress, sqrt(3/2 s:s), in the stress's unit.
inline double von_mises(const Sym& s) {
  const Sym d = deviator(s);
  return std::sqrt(1.5 * ddot(d, d));
}

}  // namespace mpm
