#pragma once
/// Crater and penetration measures of a projectile striking a target (mpm-post crater).
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "mpm/post/impact.hpp"
#include "mpm/post/symmetry.hpp"
#include "mpm/scene/scene.hpp"
#include "mpm/stream/stream.hpp"

namespace mpm {

struct CraterOptions {
  ImpactChoice impact;               ///< axis, projectile (the fastest body), target (at rest)
  std::optional<Symmetry> symmetry;  ///< the model's mirror planes; none: the scene's
};

/// How deep a body went: its deepest surface point past the target's original front surface.
struct Penetration {
  std::string body;
  double depth = 0;  ///< m; negative: short of the surface
};

struct CraterResult {
  double time = 0;  ///< s
  std::string target;
  int axis = 2, direction = 1;     ///< the impact runs along direction * axis
  Vec3 axis_point = Vec3::Zero();  ///< a point of the crater's axis (the projectile's centre)
  double spacing = 0;              ///< the target's particle spacing, m
  double surface = 0;       ///< position of the target's original front surface along the axis, m
  double thickness = 0;     ///< the whole target's original thickness along the axis, m
  bool perforated = false;  ///< no target material is left on the axis through the thickness
  /// Crater depth below the original front surface (the deepest floor inside the crater), m;
  /// perforated: the thickness.
  double depth = 0;
  /// Crater diameter at the original front surface, m; perforated: the hole's narrowest
  /// diameter through the thickness.
  double diameter = 0;
  /// The crater's floor: (radius, depth below the original surface) of radial bins two spacings
  /// wide inside the crater, m.
  std::vector<std::pair<double, double>> profile;
  std::vector<Penetration> penetration;  ///< every body but the target
  std::size_t particles = 0;             ///< target particles in the model
  Symmetry symmetry;                     ///< what the whole target was made of
};

/// Measures the crater of a target on its axis: the line along the impact through the
/// projectile's initial centre (of the whole projectile of a quarter or half model, so the
/// axis lies on the mirror planes). From the first frame: the target's front surface (its
/// particle centres nearest the projectile less half a spacing) and thickness. On a frame, of
/// the whole target's particles at depth zeta below the original surface and radius rho from the
/// axis: the crater radius is the smallest rho of those still in the original surface layer
/// (centres within half a spacing of it) less half a spacing (the wall's surface); the depth is
/// the deepest of the floors of radial bins two spacings wide inside that radius (a bin's floor:
/// its shallowest particle centre at or below the surface layer; centres and surfaces lie half
/// a spacing apart on both ends). Perforated: no target particle within a spacing of the axis
/// through the thickness; the hole's diameter is then the narrowest over layers one spacing
/// thick. Throws InputError.
class CraterMeter {
 public:
  CraterMeter(const Scene& scene, const Frame& first, const CraterOptions& options);
  CraterResult measure(const Frame& frame) const;

 private:
  Scene scene_;
  Symmetry symmetry_;
  Impact impact_;
  double spacing_ = 0;
};

}  // namespace mpm
