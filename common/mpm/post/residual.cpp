// The residual velocity of a projectile through a target (residual.hpp).
#include "mpm/post/residual.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "mpm/core/error.hpp"
#include "mpm/post/column_value.hpp"
#include "mpm/scene/particles.hpp"

namespace mpm {

namespace {

/// "a, b, c" of the scene's body names.
std::string body_names(const Scene& scene) {
  std::string s;
  for (const BodySpec& b : scene.bodies) s += (s.empty() ? "" : ", ") + b.name;
  return s;
}

int named_body(const Scene& scene, const std::string& name, const char* option) {
  const int b = scene.body_index(name);
  if (b < 0)
    throw InputError(
        option, "no body named '" + name + "' in the scene (known: " + body_names(scene) + ")");
  return b;
}

const Column& need(const Frame& f, const std::string& name) {
  const Column* c = f.columns.find(name);
  if (!c)
    throw InputError("residual", "the frames hold no column '" + name +
                                     "' (write it: output.fields in the scene)");
  return *c;
}

}  // namespace

double ResidualResult::missing_mass() const {
  const ResidualSample& e = end();
  return std::max(0.0, initial_mass - e.mass - e.failed_mass);
}

ResidualMeter::ResidualMeter(const Scene& scene, const Frame& first,
                             const ResidualOptions& options) {
  dim_ = need(first, col::x).info().components;
  r_.symmetry = options.symmetry ? *options.symmetry : scene_symmetry(scene);
  const int nb = int(scene.bodies.size());
  if (!options.body.empty()) {
    body_ = named_body(scene, options.body, "--body");
  } else {
    double best = 0;
    for (int b = 0; b < nb; ++b)
      if (scene.bodies[b].velocity.norm() > best) best = scene.bodies[b].velocity.norm(), body_ = b;
    if (body_ < 0) throw InputError("residual", "no body moves at t = 0: give --body");
  }
  r_.body = scene.bodies[body_].name;
  if (!options.target.empty()) {
    target_bodies_ = {named_body(scene, options.target, "--target")};
    if (target_bodies_[0] == body_)
      throw InputError("--target",
                       "the target must be another body than --body ('" + r_.body + "')");
  } else {
    for (int b = 0; b < nb; ++b)
      if (b != body_) target_bodies_.push_back(b);
    if (target_bodies_.empty())
      throw InputError("residual", "the scene has no body but '" + r_.body + "' to perforate");
  }
  for (int b : target_bodies_) r_.targets.push_back(scene.bodies[b].name);

  // Components zero by construction: normal to a mirror plane (a body and its image move
  // apart or together along it), and in an axisymmetric model the radius x and z.
  for (const MirrorPlane& p : r_.symmetry.planes) keep_[p.axis] = 0;
  if (r_.symmetry.axisymmetric) keep_.x() = keep_.z() = 0;
  if (dim_ == 2) keep_.z() = 0;
  for (int a = 0; a < dim_; ++a)
    if (keep_[a] == 0)
      r_.zero_components += std::string(r_.zero_components.empty() ? "" : ", ") + "xyz"[a];

  // The initial direction: the scene's velocity, else the first frame's.
  Vec3 v0 = scene.bodies[body_].velocity.cwiseProduct(keep_);
  if (v0.norm() == 0) v0 = sample(first).v;
  if (!(v0.norm() > 0))
    throw InputError("--body", "body '" + r_.body + "' does not move at t = 0 (no direction)");
  r_.direction = v0.normalized();
  r_.axis = 0;
  for (int a = 1; a < dim_; ++a)
    if (std::abs(r_.direction[a]) > std::abs(r_.direction[r_.axis])) r_.axis = a;
  r_.sign = r_.direction[r_.axis] < 0 ? -1 : 1;

  // The targets' far face: their farthest particle centre along the face normal.
  const auto* x = reinterpret_cast<const double*>(need(first, col::x).data());
  const Column& bc = need(first, col::body);
  r_.far_face = -1e300;
  for (std::size_t i = 0; i < first.columns.size(); ++i) {
    const int b = int(column_value(bc, i, 0));
    if (std::find(target_bodies_.begin(), target_bodies_.end(), b) != target_bodies_.end())
      r_.far_face = std::max(r_.far_face, r_.sign * x[i * dim_ + r_.axis]);
  }
  if (r_.far_face == -1e300)
    throw InputError("residual", "the first frame holds no target particle");
  const ResidualSample s0 = sample(first);
  if (s0.intact == 0 && s0.failed_mass == 0)
    throw InputError("--body", "the first frame holds no particle of body '" + r_.body + "'");
  r_.initial_mass = s0.mass + s0.failed_mass;
}

ResidualSample ResidualMeter::sample(const Frame& f) const {
  const Column& bc = need(f, col::body);
  const auto* x = reinterpret_cast<const double*>(need(f, col::x).data());
  const auto* v = reinterpret_cast<const double*>(need(f, col::v).data());
  const auto* m = reinterpret_cast<const double*>(need(f, col::m).data());
  const Column* fc = f.columns.find(col::failed);
  ResidualSample s;
  s.time = f.time;
  s.tail = 1e300;
  Vec3 p = Vec3::Zero();
  for (std::size_t i = 0; i < f.columns.size(); ++i) {
    if (int(column_value(bc, i, 0)) != body_) continue;
    if (fc && column_value(*fc, i, 0) != 0) {
      s.failed_mass += m[i];
      continue;
    }
    ++s.intact;
    s.mass += m[i];
    for (int a = 0; a < dim_; ++a) p[a] += m[i] * v[i * dim_ + a];
    s.tail = std::min(s.tail, r_.sign * x[i * dim_ + r_.axis]);
  }
  // The whole body: its images add mass and cancel the components normal to their planes.
  const double whole =
      r_.symmetry.images() * (r_.symmetry.axisymmetric ? 2 * std::numbers::pi : 1.0);
  s.v = s.mass > 0 ? Vec3(p.cwiseProduct(keep_) / s.mass) : Vec3::Zero();
  s.mass *= whole;
  s.failed_mass *= whole;
  s.v_along = s.v.dot(r_.direction);
  const double speed = s.v.norm();
  // atan2 of the across and along parts: accurate at small angles too (acos is not).
  s.angle = speed > 0
                ? std::atan2(s.v.cross(r_.direction).norm(), s.v_along) * 180 / std::numbers::pi
                : 0.0;
  s.out = s.intact > 0 && s.tail > r_.far_face;
  return s;
}

void ResidualMeter::add(const Frame& frame) {
  r_.history.push_back(sample(frame));
  if (!r_.exit && r_.history.back().out) r_.exit = r_.history.back();
}

}  // namespace mpm
