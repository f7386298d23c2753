// The symmetry of a model (mirror planes, axisymmetry) and the whole body it stands for.
#include "mpm/post/symmetry.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <utility>

#include "mpm/core/error.hpp"
#include "mpm/post/arguments.hpp"
#include "mpm/post/column_value.hpp"
#include "mpm/scene/particles.hpp"

namespace mpm {

namespace {

constexpr double kPi = 3.14159265358979323846;

/// The linear part of a body's placement, A = R S (scale first, then the rotations about x,
/// then y, then z), as docs/scene.md states it for bodies.
Mat3 placement(const BodySpec& b) {
  const auto about = [](int axis, double deg) {
    return Eigen::AngleAxisd(deg * kPi / 180.0, Vec3::Unit(axis)).toRotationMatrix();
  };
  const Mat3 R =
      about(2, b.rotate_deg.z()) * about(1, b.rotate_deg.y()) * about(0, b.rotate_deg.x());
  return R * b.scale.asDiagonal();
}

/// The extent of a primitive body's shape along each axis, m (lo, hi; an ogive's the box of its
/// shank's cylinder); none for a mesh (its file
/// is not in the stream).
std::optional<std::pair<Vec3, Vec3>> shape_extent(const BodySpec& b, int dim) {
  const Mat3 A = placement(b);
  const Vec3& t = b.translate;
  Vec3 lo, hi;
  for (int a = 0; a < 3; ++a) {
    double c = t[a], h = 0;  // the centre and half-width along a
    switch (b.shape) {
      case ShapeKind::Box:
        for (int j = 0; j < 3; ++j) h += std::abs(A(a, j)) * 0.5 * b.size[j];
        break;
      case ShapeKind::Sphere:
        h = b.radius * A.row(a).norm();
        break;
      case ShapeKind::Ogive:  // inside its shank's cylinder: that box (the nose never wider)
        if (dim == 2) {       // its section, along the local y from t to t + A (0, length)
          c = t[a] + 0.5 * b.length * A(a, 1);
          h = 0.5 * b.length * std::abs(A(a, 1)) + b.radius * std::abs(A(a, 0));
          break;
        }
        [[fallthrough]];
      case ShapeKind::Cylinder: {  // from the base t to t + A (0, 0, length), radius r
        c = t[a] + 0.5 * b.length * A(a, 2);
        h = 0.5 * b.length * std::abs(A(a, 2)) + b.radius * std::hypot(A(a, 0), A(a, 1));
        break;
      }
      case ShapeKind::Mesh:
        return std::nullopt;
    }
    lo[a] = c - h, hi[a] = c + h;
  }
  return std::make_pair(lo, hi);
}

std::string mm(double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g mm", x * 1e3);
  return buf;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

}  // namespace

Vec3 Symmetry::point_image(const Vec3& x, int k) const {
  Vec3 y = x;
  for (std::size_t p = 0; p < planes.size(); ++p)
    if (k >> p & 1) y[planes[p].axis] = 2 * planes[p].position - y[planes[p].axis];
  return y;
}

Vec3 Symmetry::vector_image(const Vec3& v, int k) const {
  Vec3 y = v;
  for (std::size_t p = 0; p < planes.size(); ++p)
    if (k >> p & 1) y[planes[p].axis] = -y[planes[p].axis];
  return y;
}

std::string Symmetry::describe() const {
  if (source == SymmetrySource::Option && planes.empty() && !axisymmetric)
    return "no symmetry (--symmetry none): the model as it is";
  std::string s;
  if (axisymmetric) s = "axisymmetric: the whole solid of revolution about y";
  if (planes.empty()) return s;
  s += s.empty() ? "whole body from mirror planes " : "; mirror planes ";
  for (std::size_t p = 0; p < planes.size(); ++p)
    s += (p ? ", " : "") + std::string(1, "xyz"[planes[p].axis]) + " = " + mm(planes[p].position);
  s += " (" + reason + "; " + std::to_string(images()) + " images of each particle)";
  return s;
}

Symmetry scene_symmetry(const Scene& scene) {
  Symmetry s;
  s.axisymmetric = scene.axisymmetric;
  if (!scene.grid.domain_given) return s;  // a fitted domain cuts no body
  std::vector<std::string> names;
  for (int a = 0; a < scene.dimension; ++a) {
    if (scene.axisymmetric && a == 0) continue;  // x_min is the axis, x_max no mirror
    for (int side = 0; side < 2; ++side) {
      if (scene.boundary.face[2 * a + side] != BoundaryType::Slip) continue;
      const double p = side ? scene.grid.domain_max[a] : scene.grid.domain_min[a];
      const double tol = 1e-6 * scene.grid.cell_size;
      for (const BodySpec& b : scene.bodies) {
        const auto e = shape_extent(b, scene.dimension);
        if (!e || !(e->first[a] < p - tol && e->second[a] > p + tol)) continue;
        if (!s.planes.empty() && s.planes.back().axis == a) break;  // one plane per axis
        s.planes.push_back({a, p});
        if (std::find(names.begin(), names.end(), b.name) == names.end()) names.push_back(b.name);
        break;
      }
    }
  }
  if (s.planes.empty()) return s;
  s.source = SymmetrySource::Scene;
  s.reason = "slip faces of the scene through bod";
  s.reason += names.size() > 1 ? "ies " : "y ";
  for (std::size_t i = 0; i < names.size(); ++i) s.reason += (i ? ", '" : "'") + names[i] + "'";
  return s;
}

Symmetry option_symmetry(const std::string& text, const Scene& scene, const std::string& option) {
  Symmetry s;
  s.axisymmetric = scene.axisymmetric;
  s.source = SymmetrySource::Option;
  s.reason = "given by " + option;
  if (trim(text) == "none") return s;
  const std::string& rest = text;
  std::size_t start = 0;
  while (start <= rest.size()) {
    const std::size_t end = std::min(rest.find(',', start), rest.size());
    const std::string item = trim(rest.substr(start, end - start));
    start = end + 1;
    const std::size_t eq = item.find('=');
    const std::string axis = eq == std::string::npos ? item : trim(item.substr(0, eq));
    if (eq == std::string::npos || (axis != "x" && axis != "y" && axis != "z"))
      throw InputError(option,
                       "expected 'none' or planes such as \"x = 0, y = 0 mm\", got '" + text + "'");
    const int a = axis[0] - 'x';
    if (a >= scene.dimension)
      throw InputError(option, "a " + std::to_string(scene.dimension) + "D scene has no plane " +
                                   axis + " = ...");
    if (scene.axisymmetric && a == 0)
      throw InputError(option, "an axisymmetric scene is already whole about its axis x = 0");
    for (const MirrorPlane& p : s.planes)
      if (p.axis == a) throw InputError(option, "two planes across " + axis + " in '" + text + "'");
    s.planes.push_back({a, option_quantity(trim(item.substr(eq + 1)), dim::length, option)});
  }
  std::sort(s.planes.begin(), s.planes.end(),
            [](const MirrorPlane& p, const MirrorPlane& q) { return p.axis < q.axis; });
  return s;
}

Symmetry measure_symmetry(const std::string& text, const Scene& scene) {
  return text.empty() ? scene_symmetry(scene) : option_symmetry(text, scene, "--symmetry");
}

WholeBody unfold(const Frame& frame, int dimension, const Symmetry& symmetry,
                 const std::vector<int>& bodies) {
  const Column* xc = frame.columns.find(col::x);
  const Column* bc = frame.columns.find(col::body);
  if (!xc) throw InputError("frame", "the frames hold no column 'x'");
  if (!bodies.empty() && !bc) throw InputError("frame", "the frames hold no column 'body'");
  const auto* x = reinterpret_cast<const double*>(xc->data());
  const Column* mc = frame.columns.find(col::m);
  const double* m = mc ? reinterpret_cast<const double*>(mc->data()) : nullptr;
  const std::size_t n = frame.columns.size();
  const int images = symmetry.images();
  WholeBody w;
  for (std::size_t i = 0; i < n; ++i) {
    if (!bodies.empty() &&
        std::find(bodies.begin(), bodies.end(), int(column_value(*bc, i, 0))) == bodies.end())
      continue;
    ++w.particles;
    Vec3 p = Vec3::Zero();
    for (int a = 0; a < dimension; ++a) p[a] = x[i * dimension + a];
    for (int k = 0; k < images; ++k) {
      w.x.push_back(symmetry.point_image(p, k));
      w.m.push_back(m ? m[i] : 1.0);
      w.source.push_back(i);
      w.image.push_back(k);
    }
  }
  return w;
}

void write_symmetry_json(JsonWriter& j, const Symmetry& s) {
  j.begin_object().key("planes").begin_array();
  for (const MirrorPlane& p : s.planes)
    j.begin_object()
        .key("axis")
        .string(std::string(1, "xyz"[p.axis]))
        .key("position")
        .number(p.position)
        .end_object();
  j.end_array();
  const char* source = s.source == SymmetrySource::Scene    ? "scene"
                       : s.source == SymmetrySource::Option ? "option"
                                                            : "none";
  j.key("source").string(source).key("axisymmetric").boolean(s.axisymmetric);
  j.key("images").integer(s.images()).key("reason").string(s.reason);
  j.end_object();
}

}  // namespace mpm
