// What mpm-prep checks of the bodies before it makes particles (checks.hpp): implausible
// mesh sizes (a mesh in millimetres), bodies cut by the domain.
#include "mpm/prep/checks.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "mpm/core/error.hpp"
#include "mpm/core/units.hpp"
#include "mpm/prep/body_placement.hpp"
#include "mpm/prep/region.hpp"

namespace mpm {

namespace {

/// Largest extent of the box [lo, hi] over the scene's axes (m).
double extent(const Vec3& lo, const Vec3& hi, int dim) {
  double e = 0;
  for (int a = 0; a < dim; ++a) e = std::max(e, hi[a] - lo[a]);
  return e;
}

/// "10 x 10 x 10 m": the box's edges in metres.
std::string edges_m(const Vec3& lo, const Vec3& hi, int dim) {
  std::string s;
  for (int a = 0; a < dim; ++a) s += (a ? " x " : "") + format_g6(hi[a] - lo[a]);
  return s + " m";
}

/// The hint for a mesh that is too large: its unit, and the scale to give.
std::string scale_hint(const BodySpec& body) {
  if (body.scale != Vec3::Ones())
    return "; check bodies." + body.name + ".scale (mesh files carry no unit: scale turns their " +
           "numbers into metres)";
  return "; mesh files carry no unit and are read in metres: if '" + body.mesh_path +
         "' is in millimetres, add scale = 0.001 to the body (0.0254 for inches)";
}

}  // namespace

BodyBoxes body_boxes(const Scene& scene) {
  BodyBoxes boxes;
  for (const BodySpec& body : scene.bodies) {
    Vec3 lo, hi;
    body_bounds(body, scene, lo, hi);
    if (scene.dimension == 2) lo.z() = hi.z() = 0;
    boxes.lo.push_back(lo);
    boxes.hi.push_back(hi);
  }
  return boxes;
}

void check_mesh_sizes(const Scene& scene, const BodyBoxes& boxes,
                      std::vector<std::string>& warnings) {
  const int dim = scene.dimension;
  const GridSpec& g = scene.grid;
  for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
    const BodySpec& body = scene.bodies[b];
    if (body.shape != ShapeKind::Mesh) continue;
    const double size = extent(boxes.lo[b], boxes.hi[b], dim);
    const std::string what = "body '" + body.name + "': mesh '" + body.mesh_path + "' is " +
                             format_g6(size) + " m across (" +
                             edges_m(boxes.lo[b], boxes.hi[b], dim) + ")";
    if (g.domain_given) {
      const double domain = extent(g.domain_min, g.domain_max, dim);
      if (size > 10 * domain)
        throw InputError(body_where(scene, body, "file"),
                         what + ", " + format_g6(size / domain) + " times the domain (" +
                             format_mm(domain) + " mm across)" + scale_hint(body));
      continue;
    }
    double others = 0;
    for (std::size_t j = 0; j < scene.bodies.size(); ++j)
      if (j != b) others = std::max(others, extent(boxes.lo[j], boxes.hi[j], dim));
    if (others > 0 && size > 100 * others)
      warnings.push_back(body_where(scene, body, "file") + ": " + what + ", " +
                         format_g6(size / others) + " times the largest other body (" +
                         format_mm(others) + " mm)" + scale_hint(body));
    else if (others == 0 && size > 2.0)
      warnings.push_back(body_where(scene, body, "file") + ": " + what + scale_hint(body));
  }
}

void check_domain_cuts(const Scene& scene, const Lattice& lattice, const BodyBoxes& boxes) {
  const int dim = scene.dimension;
  const Vec3 d_lo = lattice.origin, d_hi = lattice.max();
  for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
    const BodySpec& body = scene.bodies[b];
    if (body.cut_by_domain) continue;
    const double tol = 0.5 * body.spacing(lattice.h);
    const Vec3 &lo = boxes.lo[b], &hi = boxes.hi[b];
    for (int f = 0; f < 2 * dim; ++f) {
      const int a = f / 2;
      const bool at_max = f % 2 == 1;
      const double beyond = at_max ? hi[a] - d_hi[a] : d_lo[a] - lo[a];
      if (!(beyond > tol)) continue;
      // A symmetry plane cuts a body as it is meant: a slip face, the axis of revolution.
      if (scene.boundary.face[f] == BoundaryType::Slip) continue;
      if (scene.axisymmetric && f == 0 && d_lo[0] <= 0) continue;
      // The share of the body's box outside the domain, for the message.
      double inside = 1;
      for (int k = 0; k < dim; ++k)
        inside *= std::clamp(
            (std::min(hi[k], d_hi[k]) - std::max(lo[k], d_lo[k])) / std::max(hi[k] - lo[k], 1e-300),
            0.0, 1.0);
      static const char* faces[6] = {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max"};
      throw InputError(
          body_where(scene, body, ""),
          "body '" + body.name + "' is cut by the domain: it reaches " + format_mm(beyond) +
              " mm beyond its " + faces[f] + " face (domain " + axis_name(a) + " from " +
              format_mm(d_lo[a]) + " to " + format_mm(d_hi[a]) + " mm, body from " +
              format_mm(lo[a]) + " to " + format_mm(hi[a]) + " mm; " +
              format_g6(std::round(1000 * (1 - inside)) / 10) +
              "% of its bounding box is outside), and the part outside gets no particles. "
              "Enlarge grid.domain or move the body; a \"slip\" face is a symmetry plane and "
              "may cut bodies; if the cut is meant, set bodies." +
              body.name + ".cut_by_domain = true");
    }
  }
}

}  // namespace mpm
