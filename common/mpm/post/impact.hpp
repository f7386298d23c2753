#pragma once
/// The impact that the measures of a projectile striking a target look at (debris, crater,
/// and a coming residual velocity): which body strikes which, along which axis, and where the
/// target stood, all of the whole bodies of a quarter or half model (symmetry.hpp).
#include <string>

#include "mpm/core/types.hpp"
#include "mpm/post/symmetry.hpp"
#include "mpm/scene/scene.hpp"
#include "mpm/stream/stream.hpp"

namespace mpm {

/// What the user chose; empty or -1: found from the scene.
struct ImpactChoice {
  int axis = -1;           ///< impact axis 0, 1, 2; -1: the projectile's velocity direction
  std::string projectile;  ///< projectile body; empty: the fastest body at t = 0
  std::string target;      ///< target body; empty: the first body at rest at t = 0
};

struct Impact {
  int projectile = -1, target = -1;  ///< indices into Scene::bodies
  int axis = 0;                      ///< impact axis (axisymmetric: 1, the axis of revolution)
  int direction = 1;                 ///< +1 or -1: the projectile moves along +axis or -axis
  /// A point of the impact axis: the whole projectile's initial centre (axisymmetric: x = 0).
  Vec3 point = Vec3::Zero();
  /// The whole target's particle centres on the first frame nearest to and farthest from the
  /// projectile: the least and the largest direction * x[axis], m.
  double front = 0, rear = 0;
  int dimension = 3;
  /// Distance of a point from the impact axis, m.
  double radius(const Vec3& x) const {
    double r2 = 0;
    for (int a = 0; a < dimension; ++a)
      if (a != axis) r2 += (x[a] - point[a]) * (x[a] - point[a]);
    return std::sqrt(r2);
  }
};

/// Finds the impact from the scene and the first frame. `command` names the subcommand in
/// messages. Throws InputError when a named body is not in the scene, when no body moves or none
/// is at rest (give the option), or when the frame lacks the bodies.
Impact find_impact(const Scene& scene, const Frame& first, const Symmetry& symmetry,
                   const ImpactChoice& choice, const std::string& command);

}  // namespace mpm
