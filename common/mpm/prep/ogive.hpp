#pragma once
/// A projectile's shape: a cylindrical shank and a tangent-ogive nose, in its local frame (the
/// axis is +z, the base at z = 0, the nose tip at z = length), with exact inside test, volume,
/// surface area and support function; in 2D scenes its axial section (region.cpp maps the
/// local (x, y) of the plane to (x, 0, y)). Private to prep (region.cpp places it like the other
/// primitives).
#include "mpm/core/types.hpp"

namespace mpm {

/// The nose is the arc of a circle of radius rho = crh * 2R (the "calibre radius head" in shank
/// diameters) through the nose tip, tangent to the shank where the two meet: in the (z, r)
/// half-plane its centre is at (z_shank, -(rho - R)).
struct Ogive {
  /// R: the shank's radius (m); length: overall, base to tip (m); crh >= 1/2 (1/2: a hemisphere).
  Ogive(double R, double length, double crh);
  /// The nose's length (m): sqrt(rho^2 - (rho - R)^2) = R sqrt(4 crh - 1).
  static double nose_length(double R, double crh);

  /// True when the local point u (m) is inside (surface points either way).
  bool contains(const Vec3& u) const;
  /// Exact volume (m^3), nose plus shank.
  double volume() const;
  /// Exact area of the whole surface (m^2): base disk, shank's side and the nose.
  double surface_area() const;
  /// Exact area of the axial section (m^2), the plane figure |x| <= radius_at(z): a 2D scene's
  /// ogive (in plane strain a wedge-nosed plate, in axisymmetry this section revolved).
  double section_area() const;
  /// Exact perimeter of the axial section (m): base, the two shank sides and the two arcs.
  double section_perimeter() const;
  /// Support function: the largest w . u over the points u of the ogive, for any w (not
  /// necessarily unit); the extent of a placed ogive along a world axis comes from it.
  double support(const Vec3& w) const;
  /// The radius of the section at local z (m); 0 outside [0, length].
  double radius_at(double z) const;

  double R = 0;        ///< shank radius, m
  double length = 0;   ///< overall, m
  double rho = 0;      ///< the nose arc's radius, m
  double a = 0;        ///< rho - R: how far the arc's centre lies beyond the axis, m
  double L_nose = 0;   ///< the nose's length, m
  double L_shank = 0;  ///< length - L_nose, m (>= 0 for a valid ogive)
};

}  // namespace mpm
