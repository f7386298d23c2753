// The ogive projectile's geometry: shank and tangent-ogive nose (ogive.hpp).
#include "mpm/prep/ogive.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace mpm {

Ogive::Ogive(double R_, double length_, double crh)
    : R(R_), length(length_), rho(2 * crh * R_), a(2 * crh * R_ - R_) {
  L_nose = nose_length(R, crh);
  L_shank = length - L_nose;
}

double Ogive::nose_length(double R, double crh) {
  return R * std::sqrt(std::max(0.0, 4 * crh - 1));
}

bool Ogive::contains(const Vec3& u) const {
  if (!(u.z() >= 0 && u.z() <= length)) return false;
  const double r2 = u.x() * u.x() + u.y() * u.y();
  if (u.z() <= L_shank) return r2 <= R * R;
  // Nose: inside the arc's circle about (L_shank, -a) in the (z, r) half-plane.
  const double dz = u.z() - L_shank, dr = std::sqrt(r2) + a;
  return dz * dz + dr * dr <= rho * rho;
}

double Ogive::radius_at(double z) const {
  if (!(z >= 0 && z <= length)) return 0;
  if (z <= L_shank) return R;
  const double dz = z - L_shank;
  return std::max(0.0, std::sqrt(std::max(0.0, rho * rho - dz * dz)) - a);
}

double Ogive::volume() const {
  // Nose, with z from the shank's end and r(z) = sqrt(rho^2 - z^2) - a on 0 <= z <= L,
  // L = L_nose = sqrt(rho^2 - a^2):
  //   V = pi int_0^L (rho^2 - z^2 - 2 a sqrt(rho^2 - z^2) + a^2) dz
  //     = pi [(rho^2 + a^2) L - L^3/3 - a (L sqrt(rho^2 - L^2) + rho^2 asin(L / rho))]
  //     = pi [rho^2 L - L^3/3 - a rho^2 asin(L / rho)]        (sqrt(rho^2 - L^2) = a).
  // A hemisphere (crh = 1/2: a = 0, L = rho = R) gives 2/3 pi R^3. Shank: pi R^2 L_shank.
  const double pi = std::numbers::pi, L = L_nose;
  const double nose = pi * (rho * rho * L - L * L * L / 3 - a * rho * rho * std::asin(L / rho));
  return nose + pi * R * R * L_shank;
}

double Ogive::surface_area() const {
  // Nose: the arc at angle t from the r direction, r = rho cos t - a, ds = rho dt, t from 0 to
  // t_m = asin(L / rho): S = 2 pi rho int_0^t_m (rho cos t - a) dt = 2 pi rho (L - a t_m).
  const double pi = std::numbers::pi;
  const double nose = 2 * pi * rho * (L_nose - a * std::asin(L_nose / rho));
  return nose + 2 * pi * R * L_shank + pi * R * R;
}

double Ogive::section_area() const {
  // Twice the half-section: int_0^L (sqrt(rho^2 - z^2) - a) dz = (L a + rho^2 asin(L / rho)) / 2
  // - a L (sqrt(rho^2 - L^2) = a) for the nose, R L_shank for the shank. A hemisphere (a = 0,
  // L = rho = R): pi R^2 / 4 a half, a half-disk whole.
  const double L = L_nose;
  const double half_nose = 0.5 * (rho * rho * std::asin(L / rho) - a * L);
  return 2 * (half_nose + R * L_shank);
}

double Ogive::section_perimeter() const {
  // Each arc subtends asin(L / rho) at its centre.
  return 2 * R + 2 * L_shank + 2 * rho * std::asin(L_nose / rho);
}

double Ogive::support(const Vec3& w) const {
  // w . u = w_z z + q r on the profile (z, r), q = |(w_x, w_y)| >= 0 (the best azimuth). On
  // the shank it is linear in z: its ends. On the arc (z, r) = (L_shank, -a) + rho (sin t,
  // cos t), 0 <= t <= t_m, it is w_z L_shank - q a + rho (w_z sin t + q cos t), largest at
  // t = atan2(w_z, q) when that lies on the arc, else at an end (the shank's end or the tip).
  const double q = std::hypot(w.x(), w.y()), wz = w.z();
  double h = std::max({q * R, wz * L_shank + q * R, wz * length});
  const double t = std::atan2(wz, q), t_m = std::asin(std::min(1.0, L_nose / rho));
  if (t >= 0 && t <= t_m) h = std::max(h, wz * L_shank - q * a + rho * std::hypot(wz, q));
  return h;
}

}  // namespace mpm
