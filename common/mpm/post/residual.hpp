#pragma once
/// The residual velocity of a projectile through a target (mpm-post residual): the body's
/// velocity against time, mass-weighted over its particles that have not failed, its speed and
/// exit angle when its tail has left the target and at the end, and its mass lost to failure.
/// Of the whole body of a quarter or half model (symmetry.hpp).
#include <optional>
#include <string>
#include <vector>

#include "mpm/post/symmetry.hpp"
#include "mpm/scene/scene.hpp"
#include "mpm/stream/stream.hpp"

namespace mpm {

struct ResidualOptions {
  std::string body;                  ///< the projectile; empty: the fastest body at t = 0
  std::string target;                ///< the target; empty: every other body
  std::optional<Symmetry> symmetry;  ///< the model's mirror planes; none: the scene's
};

/// The body on one frame.
struct ResidualSample {
  double time = 0;         ///< s
  Vec3 v = Vec3::Zero();   ///< mass-weighted velocity of its intact particles, m/s
  double v_along = 0;      ///< v . d0, the component along the initial direction, m/s
  double angle = 0;        ///< angle between v and d0, degrees (0 when v = 0)
  double mass = 0;         ///< the intact particles' mass, kg (the whole body's)
  double failed_mass = 0;  ///< the failed particles' mass, kg (the whole body's)
  double tail = 0;         ///< the rearmost intact particle, s x[axis], m
  bool out = false;        ///< the tail is past the target's far face
  std::size_t intact = 0;  ///< intact particles of the model
};

struct ResidualResult {
  std::string body;
  std::vector<std::string> targets;  ///< the bodies the tail must leave behind
  Vec3 direction = Vec3::UnitZ();    ///< d0, the unit initial direction of travel
  int axis = 2, sign = 1;            ///< the face normal: the axis nearest d0, and its sign
  double far_face = 0;      ///< the targets' far face on the first frame, max of sign x[axis], m
  double initial_mass = 0;  ///< the body's whole mass on the first frame, kg
  std::vector<ResidualSample> history;  ///< one per frame, in time order
  /// The first frame whose tail is past the far face; none when the body never got through.
  std::optional<ResidualSample> exit;
  /// Velocity components that are zero by construction (mirror planes normal to them, and the
  /// radius and z of an axisymmetric model), e.g. "y".
  std::string zero_components;
  Symmetry symmetry;
  const ResidualSample& end() const { return history.back(); }
  /// The whole body's mass no longer in the frames (particles that left the domain), kg.
  double missing_mass() const;
};

/// Measures frame after frame. The first frame (the first given) fixes the initial direction
/// (the body's scene velocity, or its mass-weighted velocity on that frame when the scene
/// gives none), the targets' far face and the initial mass.
class ResidualMeter {
 public:
  /// Throws InputError naming --body (with the known bodies) or --target when a name is not
  /// in the scene, when the frame lacks the columns x, v, m, body or the body's particles, or
  /// when the body does not move.
  ResidualMeter(const Scene& scene, const Frame& first, const ResidualOptions& options);
  /// Adds a frame's sample to the history.
  void add(const Frame& frame);
  const ResidualResult& result() const { return r_; }

 private:
  ResidualSample sample(const Frame& frame) const;

  int body_ = -1, dim_ = 3;
  std::vector<int> target_bodies_;
  Vec3 keep_ = Vec3::Ones();  ///< 1 for each component kept, 0 for those zero by symmetry
  ResidualResult r_;
};

}  // namespace mpm
