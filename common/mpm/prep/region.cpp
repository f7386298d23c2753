// Bodies' regions: the primitives (box, cylinder, sphere, ogive; rectangle and disk in 2D) with
// exact inside tests and volumes, the checks of a body's shape and placement, and the lattice
// fitted around the bodies. Mesh regions (CGAL) live in mesh_region.cpp.
#include "mpm/prep/region.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "mpm/core/error.hpp"
#include "mpm/core/units.hpp"
#include "mpm/prep/body_placement.hpp"
#include "mpm/prep/mesh_region.hpp"
#include "mpm/prep/ogive.hpp"

namespace mpm {

namespace {

const char* shape_name(ShapeKind k) {
  switch (k) {
    case ShapeKind::Box:
      return "box";
    case ShapeKind::Cylinder:
      return "cylinder";
    case ShapeKind::Sphere:
      return "sphere";
    case ShapeKind::Ogive:
      return "ogive";
    case ShapeKind::Mesh:
      return "mesh";
  }
  return "?";
}

bool finite(const Vec3& v) {
  return v.allFinite();
}

/// Box, cylinder, sphere and ogive (rectangle and disk in 2D). contains() maps the point back to
/// the local frame with the precomputed inverse placement, x_local = S^-1 R^T (x - t), and tests
/// the local shape exactly.
class PrimitiveRegion final : public Region {
 public:
  PrimitiveRegion(const BodySpec& body, int dim)
      : kind_(body.shape), dim_(dim), ogive_(body.radius, body.length, body.crh) {
    Mat3 A = body_linear_map(body);
    Vec3 s = body.scale;
    t_ = body.translate;
    if (dim == 2) {
      // x-y plane only: no z scale, no z translation.
      A.row(2).setZero();
      A.col(2).setZero();
      A(2, 2) = 1;
      s.z() = 1;
      t_.z() = 0;
    }
    to_local_ = s.cwiseInverse().asDiagonal() * body_rotation(body).transpose();
    A_ = A;
    const double ascale = std::abs(s.x() * s.y() * s.z());
    r2_ = body.radius * body.radius;
    half_ = 0.5 * body.size;
    length_ = body.length;
    const double pi = std::numbers::pi;
    switch (kind_) {
      case ShapeKind::Box: {
        // Half extent along world axis a: sum_j |A_aj| half_j.
        Vec3 h = half_;
        if (dim == 2) h.z() = 0;
        const Vec3 e = A.cwiseAbs() * h;
        lo_ = t_ - e;
        hi_ = t_ + e;
        volume_ = (dim == 2 ? body.size.x() * body.size.y() : body.size.prod()) * ascale;
        break;
      }
      case ShapeKind::Sphere: {
        // Ellipsoid {A u + t : |u| <= r}: half extent along a is r |row a of A|.
        Vec3 e;
        for (int a = 0; a < 3; ++a) e[a] = body.radius * A.row(a).norm();
        if (dim == 2) e.z() = 0;
        lo_ = t_ - e;
        hi_ = t_ + e;
        volume_ = (dim == 2 ? pi * r2_ : 4.0 / 3.0 * pi * r2_ * body.radius) * ascale;
        break;
      }
      case ShapeKind::Cylinder: {
        // Union of the end disks' boxes: a disk {A (u, v, 0) + c : u^2 + v^2 <= r^2} has half
        // extent r sqrt(A_a0^2 + A_a1^2) along a.
        Vec3 e;
        for (int a = 0; a < 3; ++a) e[a] = body.radius * std::hypot(A(a, 0), A(a, 1));
        const Vec3 top = t_ + A * Vec3(0, 0, body.length);
        lo_ = t_.cwiseMin(top) - e;
        hi_ = t_.cwiseMax(top) + e;
        volume_ = pi * r2_ * body.length * ascale;
        break;
      }
      case ShapeKind::Ogive:
        // Along world axis a the ogive reaches t_a + h(A^T e_a) and t_a - h(-A^T e_a), h its
        // support function in the local frame (in 2D the plane's local (x, y) is the ogive's
        // (x, 0, y): its axis along the body's local y).
        for (int a = 0; a < 3; ++a) {
          Vec3 w = A.row(a).transpose();
          if (dim == 2) w = Vec3(w.x(), 0, w.y());
          lo_[a] = t_[a] - ogive_.support(-w);
          hi_[a] = t_[a] + ogive_.support(w);
        }
        if (dim == 2) lo_.z() = hi_.z() = 0;
        volume_ = (dim == 2 ? ogive_.section_area() : ogive_.volume()) * ascale;
        break;
      case ShapeKind::Mesh:
        break;  // not a primitive
    }
  }

  bool contains(const Vec3& x) const override {
    const Vec3 p = to_local_ * (x - t_);
    switch (kind_) {
      case ShapeKind::Box:
        return std::abs(p.x()) <= half_.x() && std::abs(p.y()) <= half_.y() &&
               (dim_ == 2 || std::abs(p.z()) <= half_.z());
      case ShapeKind::Sphere:
        return (dim_ == 2 ? p.x() * p.x() + p.y() * p.y() : p.squaredNorm()) <= r2_;
      case ShapeKind::Cylinder:
        return p.z() >= 0 && p.z() <= length_ && p.x() * p.x() + p.y() * p.y() <= r2_;
      case ShapeKind::Ogive:
        return ogive_.contains(dim_ == 2 ? Vec3(p.x(), 0, p.y()) : p);
      case ShapeKind::Mesh:
        return false;
    }
    return false;
  }
  double volume() const override { return volume_; }
  void bounds(Vec3& lo, Vec3& hi) const override {
    lo = lo_;
    hi = hi_;
  }

  double revolved_volume() const override {
    if (dim_ != 2) return Region::revolved_volume();
    if (kind_ == ShapeKind::Ogive) {
      // On the axis (check_body_shape): the solid of revolution of the section, scaled by s_x
      // radially and s_y along the axis: s_x^2 s_y V / (2 pi) per radian.
      return A_(0, 0) * A_(0, 0) * std::abs(A_(1, 1)) * ogive_.volume() / (2 * std::numbers::pi);
    }
    if (kind_ == ShapeKind::Sphere) {
      // The ellipse {A u + t : |u| <= R}: x = a.u + t_x with a the first row of A. With w the
      // coordinate of u along a, the integral of x over x >= 0 is |det A| times the integral
      // of (|a| w + t_x) 2 sqrt(R^2 - w^2) over w from max(-R, -t_x / |a|) to R.
      const double detA = std::abs(A_(0, 0) * A_(1, 1) - A_(0, 1) * A_(1, 0));
      const double R = std::sqrt(r2_), alpha = std::hypot(A_(0, 0), A_(0, 1));
      const double w0 = std::clamp(-t_.x() / alpha, -R, R);
      auto root = [&](double w) {
        return std::sqrt(std::max(0.0, (R - w) * (R + w)));
      };                        // 0 at w = +-R
      auto F = [&](double w) {  // of 2 sqrt(R^2 - w^2)
        return w * root(w) + R * R * std::asin(std::clamp(w / R, -1.0, 1.0));
      };
      auto G = [&](double w) {
        return -2.0 / 3.0 * std::pow(root(w), 3);
      };  // of 2 w sqrt(R^2 - w^2)
      return detA * (t_.x() * (F(R) - F(w0)) + alpha * (G(R) - G(w0)));
    }
    // The parallelogram of the box's corners, clipped to x >= 0 (one half-plane of
    // Sutherland-Hodgman); its integral of x by the polygon formula
    // (1/6) sum (x_i + x_j) (x_i y_j - x_j y_i), j = i + 1.
    std::vector<Vec<2>> in, out;
    for (const auto& [i, j] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
      const Vec3 c = A_ * Vec3(i * half_.x(), j * half_.y(), 0) + t_;
      in.emplace_back(c.x(), c.y());
    }
    for (std::size_t k = 0; k < in.size(); ++k) {
      const Vec<2>&p = in[k], &q = in[(k + 1) % in.size()];
      if (p.x() >= 0) out.push_back(p);
      if ((p.x() >= 0) != (q.x() >= 0))
        out.emplace_back(0.0, p.y() + (q.y() - p.y()) * (0 - p.x()) / (q.x() - p.x()));
    }
    double moment = 0;
    for (std::size_t k = 0; k < out.size(); ++k) {
      const Vec<2>&p = out[k], &q = out[(k + 1) % out.size()];
      moment += (p.x() + q.x()) * (p.x() * q.y() - q.x() * p.y());
    }
    return std::abs(moment) / 6.0;
  }

 private:
  ShapeKind kind_;
  int dim_;
  Mat3 A_;
  Mat3 to_local_;
  Vec3 t_, half_, lo_, hi_;
  double r2_ = 0, length_ = 0, volume_ = 0;
  Ogive ogive_;  ///< its geometry for ShapeKind::Ogive
};

/// Checks a body's shape parameters and placement; throws InputError at the offending key.
void check_body_shape(const BodySpec& body, const Scene& scene) {
  const int dim = scene.dimension;
  if (dim == 2 && body.shape != ShapeKind::Box && body.shape != ShapeKind::Sphere &&
      body.shape != ShapeKind::Ogive)
    throw InputError(body_where(scene, body, "shape"),
                     "body '" + body.name + "' has shape " + shape_name(body.shape) +
                         "; a 2D scene takes only box (a rectangle), sphere (a disk) and ogive "
                         "(its axial section)");
  for (int a = 0; a < dim; ++a)
    if (!(body.scale[a] != 0) || !std::isfinite(body.scale[a]))
      throw InputError(body_where(scene, body, "scale"),
                       std::string("the scale along ") + axis_name(a) +
                           " must be a non-zero number (got " + format_g6(body.scale[a]) + ")");
  if (!finite(body.rotate_deg))
    throw InputError(body_where(scene, body, "rotate"), "the rotation must be finite");
  if (!finite(body.translate))
    throw InputError(body_where(scene, body, "translate"), "the translation must be finite");
  if (dim == 2 && (body.rotate_deg.x() != 0 || body.rotate_deg.y() != 0))
    throw InputError(body_where(scene, body, "rotate"),
                     "a 2D scene rotates bodies only about z; the x and y angles must be 0");
  switch (body.shape) {
    case ShapeKind::Box:
      for (int a = 0; a < dim; ++a)
        if (!(body.size[a] > 0) || !std::isfinite(body.size[a]))
          throw InputError(body_where(scene, body, "size"),
                           std::string("the box's edge along ") + axis_name(a) +
                               " must be a positive length in m (got " + format_g6(body.size[a]) +
                               ")");
      break;
    case ShapeKind::Cylinder:
      if (!(body.length > 0) || !std::isfinite(body.length))
        throw InputError(
            body_where(scene, body, "length"),
            "the cylinder's length must be positive, in m (got " + format_g6(body.length) + ")");
      [[fallthrough]];
    case ShapeKind::Sphere:
      if (!(body.radius > 0) || !std::isfinite(body.radius))
        throw InputError(
            body_where(scene, body, "radius"),
            "the radius must be a positive length in m (got " + format_g6(body.radius) + ")");
      break;
    case ShapeKind::Ogive: {
      if (!(body.radius > 0) || !std::isfinite(body.radius))
        throw InputError(body_where(scene, body, "diameter"),
                         "the shank's diameter must be a positive length in m (got " +
                             format_g6(2 * body.radius) + ")");
      if (!(body.crh >= 0.5) || !std::isfinite(body.crh))
        throw InputError(body_where(scene, body, "crh"),
                         "the nose's arc radius must be at least half a diameter (0.5: a "
                         "hemispherical nose; got " +
                             format_g6(body.crh) + ")");
      const double nose = Ogive::nose_length(body.radius, body.crh);
      if (!(body.length >= nose) || !std::isfinite(body.length))
        throw InputError(body_where(scene, body, "length"),
                         "the ogive's overall length must be at least its nose's, " +
                             format_g6(nose * 1e3) + " mm for crh " + format_g6(body.crh) +
                             " and diameter " + format_g6(2e3 * body.radius) + " mm (got " +
                             format_g6(body.length * 1e3) + " mm)");
      if (dim == 2 && scene.axisymmetric) {
        // Revolved about the scene's axis the section must give the projectile, not a ring: its
        // axis on x = 0, pointing along +y or -y.
        const Mat3 A = body_linear_map(body);
        const double tol = 1e-9 * body.length;
        if (!(std::abs(body.translate.x()) <= tol))
          throw InputError(body_where(scene, body, "translate"),
                           "in an axisymmetric scene an ogive's base centre must lie on the axis, "
                           "x = 0 (got x = " +
                               format_g6(body.translate.x() * 1e3) + " mm)");
        if (!(std::abs(A(0, 1)) <= 1e-12 * std::abs(A(1, 1)) &&
              std::abs(A(1, 0)) <= 1e-12 * std::abs(A(0, 0))))
          throw InputError(body_where(scene, body, "rotate"),
                           "in an axisymmetric scene an ogive points along the axis: rotate = 0 "
                           "(nose towards +y) or 180 (towards -y), got " +
                               format_g6(body.rotate_deg.z()) + " deg");
      }
      break;
    }
    case ShapeKind::Mesh:
      break;  // checked when the file is read
  }
}

}  // namespace

void body_bounds(const BodySpec& body, const Scene& scene, Vec3& lo, Vec3& hi) {
  check_body_shape(body, scene);
  if (body.shape == ShapeKind::Mesh) {
    mesh_body_bounds(body, scene, lo, hi);
  } else {
    PrimitiveRegion(body, scene.dimension).bounds(lo, hi);
  }
}

std::unique_ptr<Region> make_region(const BodySpec& body, const Scene& scene) {
  check_body_shape(body, scene);
  if (body.shape == ShapeKind::Mesh) return std::make_unique<MeshRegion>(body, scene);
  return std::make_unique<PrimitiveRegion>(body, scene.dimension);
}

Lattice fit_lattice(const Scene& scene) {
  if (scene.grid.domain_given) return make_lattice(scene);
  std::vector<Vec3> lo, hi;
  for (const BodySpec& b : scene.bodies) {
    lo.emplace_back();
    hi.emplace_back();
    body_bounds(b, scene, lo.back(), hi.back());
  }
  return fit_lattice(scene, lo, hi);
}

Lattice fit_lattice(const Scene& scene, const std::vector<Vec3>& body_lo,
                    const std::vector<Vec3>& body_hi) {
  const GridSpec& g = scene.grid;
  if (g.domain_given) return make_lattice(scene);
  check_lattice_scene(scene);
  if (!(g.padding >= 0) || !std::isfinite(g.padding))
    throw InputError(where(scene.source, g.loc.line, "grid.padding"),
                     "the padding must be a length >= 0 in m (got " + format_g6(g.padding) + ")");
  if (scene.bodies.empty())
    throw InputError(where(scene.source, g.loc.line, "grid.domain"),
                     "no domain is given and there is no body to fit one around");
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -lo;
  for (std::size_t b = 0; b < body_lo.size(); ++b) {
    lo = lo.cwiseMin(body_lo[b]);
    hi = hi.cwiseMax(body_hi[b]);
  }
  lo.array() -= g.padding;
  hi.array() += g.padding;
  return make_lattice(scene, lo, hi);
}

double Region::revolved_volume() const {
  throw std::logic_error(
      "revolved_volume: only the 2D primitives (boxes and disks) sweep a solid of revolution");
}

}  // namespace mpm
