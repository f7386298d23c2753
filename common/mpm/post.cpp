#include "mpm/post.hpp"

#include <algorithm>
#include <cmath>

#include "mpm/error.hpp"
#include "mpm/particles.hpp"

namespace mpm {

TaylorMeter::TaylorMeter(const Scene& scene, const TaylorOptions& options)
    : scene_(scene), opt_(options) {
  if (scene_.bodies.empty()) throw InputError("taylor", "the scene has no bodies");
  body_ = 0;
  if (!opt_.body.empty()) {
    body_ = -1;
    for (std::size_t b = 0; b < scene_.bodies.size(); ++b)
      if (scene_.bodies[b].name == opt_.body) body_ = int(b);
    if (body_ < 0) throw InputError("--body", "no body named '" + opt_.body + "' in the scene");
  }
}

TaylorResult TaylorMeter::measure(const Frame& frame) const {
  const int d = scene_.dimension;
  const Column* xc = frame.columns.find(col::x);
  const Column* bc = frame.columns.find(col::body);
  if (!xc || !bc) throw InputError("taylor", "frames need the columns 'x' and 'body'");
  const auto* x = reinterpret_cast<const double*>(xc->data());
  const auto* body = reinterpret_cast<const std::uint8_t*>(bc->data());
  const std::size_t n = frame.columns.size();
  const Column* mc = frame.columns.find(col::m);
  const double* m = mc ? reinterpret_cast<const double*>(mc->data()) : nullptr;

  TaylorResult r;
  r.time = frame.time;
  const BodySpec& spec = scene_.bodies[body_];
  r.spacing = scene_.grid.cell_size / spec.particles_per_cell;
  r.measure = opt_.surface ? "surface" : "centres";

  // Bounding box and mass centre of the body's particles.
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300), centre = Vec3::Zero();
  double mass = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (body[i] != body_) continue;
    ++r.particles;
    const double w = m ? m[i] : 1.0;
    for (int a = 0; a < d; ++a) {
      lo[a] = std::min(lo[a], x[i * d + a]);
      hi[a] = std::max(hi[a], x[i * d + a]);
      centre[a] += w * x[i * d + a];
    }
    mass += w;
  }
  if (r.particles == 0)
    throw InputError("taylor", "body '" + spec.name + "' has no particles in the frame at t = " +
                                   std::to_string(frame.time) + " s");
  centre /= mass;

  // Axis: as given, else the longest extent of the body.
  r.axis = opt_.axis;
  if (r.axis < 0) {
    r.axis = 0;
    for (int a = 1; a < d; ++a)
      if (hi[a] - lo[a] > hi[r.axis] - lo[r.axis]) r.axis = a;
  }
  const int ax = r.axis;
  // Wall: as given, else the constrained domain face along the axis nearest to the body.
  if (opt_.wall) {
    r.wall = *opt_.wall;
  } else {
    const Vec3& dmin = scene_.grid.domain_min;
    const Vec3& dmax = scene_.grid.domain_max;
    const bool at_min = scene_.boundary.face[2 * ax] != BoundaryType::Free;
    const bool at_max = scene_.boundary.face[2 * ax + 1] != BoundaryType::Free;
    if (!at_min && !at_max)
      throw InputError("taylor", std::string("no constrained domain face across axis ") +
                                     "xyz"[ax] + " to act as the wall; give --wall");
    if (at_min && (!at_max || lo[ax] - dmin[ax] <= dmax[ax] - hi[ax])) r.wall = dmin[ax];
    else r.wall = dmax[ax];
  }

  double L = 0, R = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (body[i] != body_) continue;
    L = std::max(L, std::abs(x[i * d + ax] - r.wall));
    double r2 = 0;
    for (int a = 0; a < d; ++a)
      if (a != ax) r2 += (x[i * d + a] - centre[a]) * (x[i * d + a] - centre[a]);
    R = std::max(R, std::sqrt(r2));
  }
  r.L = L + (opt_.surface ? 0.5 * r.spacing : 0.0);
  r.D = 2 * R + (opt_.surface ? r.spacing : 0.0);
  return r;
}

}  // namespace mpm
