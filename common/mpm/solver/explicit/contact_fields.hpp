#pragma once
/// The velocity fields of multi-body contact (004, section 5.4; Bardenhagen et al. 2001; Huang
/// et al. 2011): each body named in a [[contact]] pair has its own nodal mass, momentum, force,
/// mass gradient and (MUSL) remapped momentum; every other body stays in the grid's common
/// field. Field 0 is the common field (the grid's own arrays), field k + 1 is fields[k]. Only
/// a scene with [[contact]] holds any of this.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "mpm/core/error.hpp"
#include "mpm/core/types.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm {

/// Distance, in cells, from the mass centre of a body at a node to its surface, when the body
/// fills a share `phi` of the node's support on one side of a plane and the linear shape
/// function N = 1 - |z| / h weighs it (along the normal; the directions along the plane
/// cancel). With the surface at u (cells, from the node) and the body beyond it:
///   phi <= 1/2 (u >= 0): the body covers a triangle of the hat from u to 1, its centre a third
///     of the way: d = (1 - u) / 3 = sqrt(2 phi) / 3;
///   phi > 1/2 (u < 0): the hat less the triangle from -1 to u (weight 1 - phi, centre
///     u - (1 + u) / 3, 1 + u = sqrt(2 (1 - phi))); the hat's first moment is zero, so the
///     body's centre is -(1 - phi) z_m / phi and d its distance from u.
/// d(1/2) = 1/3 from both sides; d(0) = 0, d(1) = 1.
inline double centre_to_surface(double phi) {
  phi = std::clamp(phi, 0.0, 1.0);
  if (phi <= 0.5) return std::sqrt(2.0 * phi) / 3.0;
  const double s = std::sqrt(2.0 * (1.0 - phi));  // 1 + u
  const double u = s - 1.0;
  const double z_m = u - s / 3.0;  // centre of the part of the hat the body leaves empty
  return -(1.0 - phi) * z_m / phi - u;
}

/// How far apart (cells, along the normal) the mass centres of two bodies touching along a
/// plane are at a node where the first holds the share phi_a of the two bodies' volume there:
/// 2/3 when they share the node equally, up to 1 where one barely reaches it. At two particles
/// a cell per axis the centres of touching bodies lie -0.04 to +0.12 cells from this (the
/// particles' discreteness; three a cell: -0.02 to +0.08; one: +0.13 to +0.33), so a
/// `separation` of 0.125 never misses touching bodies at two a cell. Bodies apart leave part of
/// the node empty, which the shares do not see: the estimate falls short of a real gap (by
/// up to 0.08 cells at a quarter cell), but a quarter cell apart still reads more than 0.125
/// (test Contact.TouchingGapFollowsTheShareOfTheNode).
inline double touching_gap(double phi_a) {
  return centre_to_surface(phi_a) + centre_to_surface(1.0 - phi_a);
}

template <int D>
class ContactFields {
 public:
  /// The most fields a node can exchange momentum between (the common one and 31 bodies).
  static constexpr int kMaxFields = 32;

  /// Node arrays of one body's field, indexed like the grid's.
  struct Field {
    std::vector<double> m;  ///< mass, kg
    std::vector<Vec<D>> v;  ///< momentum, then velocity
    std::vector<Vec<D>> a;  ///< force, then acceleration
    std::vector<Vec<D>> g;  ///< mass gradient sum_p m_p grad N_i(x_p), kg/m (outward)
    std::vector<Vec<D>> q;  ///< MUSL: remapped momentum, then velocity
    std::vector<Vec<D>> x;  ///< sum_p m_p N_i(x_p) x_p, kg m: the field's centre at the node
    std::vector<double> V;  ///< sum_p V_p N_i(x_p), m^3 (pairs with `separation` only)
  };

  /// The fields of the scene's [[contact]] bodies (none without contact). Throws InputError
  /// when more than kMaxFields - 1 bodies are in contact.
  explicit ContactFields(const Scene& scene) : field_of_body_(scene.bodies.size(), 0) {
    for (const auto& c : scene.contacts)
      for (int b : {c.body_a, c.body_b})
        if (field_of_body_[b] == 0) {
          if (int(fields_.size()) + 1 >= kMaxFields)
            throw InputError(
                where(c.loc.file, c.loc.line, c.loc.key),
                "at most " + std::to_string(kMaxFields - 1) + " bodies can be in contact");
          fields_.emplace_back();
          field_of_body_[b] = std::uint8_t(fields_.size());
        }
    const int F = field_count();
    friction_.assign(std::size_t(F * F), -1.0);
    gap_.assign(std::size_t(F * F), 0.0);
    separation_.assign(std::size_t(F * F), -1.0);
    pair_.assign(std::size_t(F * F), -1);
    normal_.assign(std::size_t(F * F), kSteeper);
    for (std::size_t k = 0; k < scene.contacts.size(); ++k) {
      const ContactSpec& c = scene.contacts[k];
      const int a = field_of_body_[c.body_a], b = field_of_body_[c.body_b];
      friction_[a * F + b] = friction_[b * F + a] = c.friction;
      gap_[a * F + b] = gap_[b * F + a] = c.gap;
      separation_[a * F + b] = separation_[b * F + a] = c.separation;
      if (c.separation >= 0) surfaces_ = true;
      using N = ContactSpec::Normal;
      const int own = c.normal == N::BodyA ? a : c.normal == N::BodyB ? b : -1;
      normal_[a * F + b] = normal_[b * F + a] = own >= 0                 ? own
                                                : c.normal == N::Average ? kAverage
                                                                         : kSteeper;
      pair_[std::min(a, b) * F + std::max(a, b)] = int(k);
      sign_.push_back(a < b ? 1.0 : -1.0);
    }
    force_.assign(scene.contacts.size(), Vec3::Zero());
  }

  /// True when the scene has contact (any field besides the common one).
  bool active() const { return !fields_.empty(); }
  /// Fields including the common one.
  int field_count() const { return 1 + int(fields_.size()); }
  /// Field of a body: 0 (common) or k + 1.
  int field_of(std::uint8_t body) const { return field_of_body_[body]; }
  Field& field(int f) { return fields_[f - 1]; }
  const Field& field(int f) const { return fields_[f - 1]; }
  /// Coulomb coefficient between fields a and b; negative: not a contact pair (they stick).
  double friction(int a, int b) const { return friction_[a * field_count() + b]; }
  /// Where the normal between fields a and b comes from: kSteeper (the steeper mass gradient),
  /// kAverage (the difference of the two), or a field (that field's gradient).
  static constexpr int kSteeper = -1, kAverage = -2;
  int normal_from(int a, int b) const { return normal_[a * field_count() + b]; }
  /// Index of the [[contact]] pair of fields a < b, or -1.
  int pair(int a, int b) const { return pair_[a * field_count() + b]; }
  /// +1 when the first body the pair names has the lower field, else -1: the force on it
  /// is sign(k) times the force on field a of pair(a, b) = k.
  double sign(int k) const { return sign_[k]; }
  /// Force (N) on the first body of each [[contact]] pair from the second in the last step.
  const std::vector<Vec3>& force() const { return force_; }
  std::vector<Vec3>& force() { return force_; }
  /// Per node, the pairs of fields in contact after the last grid update (bit s: the s-th
  /// pair of the fields present at the node, in field order); MUSL's remap follows them.
  std::vector<std::uint64_t>& held() { return held_; }
  /// Gap below which fields a and b touch at a node, in cells (distance of their centres
  /// there; the pair's `gap`): for two particles a cell per axis, bodies touching anywhere in
  /// a cell put those centres 0.70 to 0.98 cells apart (linear shape functions).
  double touch(int a, int b) const { return gap_[a * field_count() + b]; }
  /// The pair's `separation` (cells), or negative where the pair uses `gap`.
  double separation(int a, int b) const { return separation_[a * field_count() + b]; }

  /// Sizes every field to `nodes` nodes and zeroes mass, momentum, force and mass gradient
  /// (and the remapped momentum when `remap`).
  void clear(std::size_t nodes, bool remap) {
    held_.resize(nodes);
    for (Field& f : fields_) {
      const std::int64_t n = std::int64_t(nodes);
      f.m.resize(nodes), f.v.resize(nodes), f.a.resize(nodes), f.g.resize(nodes);
      f.x.resize(nodes);
      if (surfaces_) f.V.resize(nodes);
      if (remap) f.q.resize(nodes);
#pragma omp parallel for schedule(static)
      for (std::int64_t i = 0; i < n; ++i) {
        f.m[i] = 0;
        f.v[i].setZero(), f.a[i].setZero(), f.g[i].setZero(), f.x[i].setZero();
        if (surfaces_) f.V[i] = 0;
        if (remap) f.q[i].setZero();
      }
    }
  }
  /// Bytes of the fields' node arrays.
  std::size_t bytes() const {
    std::size_t b = 0;
    for (const Field& f : fields_)
      b += (f.m.capacity() + f.V.capacity()) * sizeof(double) +
           (f.v.capacity() + f.a.capacity() + f.g.capacity() + f.q.capacity() + f.x.capacity()) *
               sizeof(Vec<D>);
    b += held_.capacity() * sizeof(std::uint64_t);
    return b;
  }

 private:
  std::vector<Field> fields_;
  std::vector<std::uint8_t> field_of_body_;
  std::vector<double> friction_;
  std::vector<double> gap_;
  std::vector<double> separation_;
  bool surfaces_ = false;
  std::vector<int> normal_;
  std::vector<int> pair_;
  std::vector<double> sign_;
  std::vector<Vec3> force_;
  std::vector<std::uint64_t> held_;
};

}  // namespace mpm
