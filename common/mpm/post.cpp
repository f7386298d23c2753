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

namespace {

/// p-th percentile (0..100) of values, by the nearest-rank rule on a sorted copy: the
/// ceil(p n / 100)-th smallest. p n / 100 is rounded first (99.9 has no exact binary form, and
/// 99.9 / 100 * 1000 would otherwise round up to the 1000th value).
double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const double rank = std::ceil(p / 100.0 * double(v.size()) * (1 - 1e-12));
  const std::size_t k = std::min(v.size() - 1, std::size_t(std::max(rank, 1.0)) - 1);
  return v[p <= 0 ? 0 : k];
}

}  // namespace

DebrisMeter::DebrisMeter(const Scene& scene, const Frame& first, const DebrisOptions& options)
    : opt_(options) {
  const Column* xc = first.columns.find(col::x);
  const Column* vc = first.columns.find(col::v);
  const Column* bc = first.columns.find(col::body);
  if (!xc || !vc || !bc) throw InputError("debris", "frames need the columns 'x', 'v' and 'body'");
  dim_ = xc->info().components;
  const auto* x = reinterpret_cast<const double*>(xc->data());
  const auto* v = reinterpret_cast<const double*>(vc->data());
  const auto* body = reinterpret_cast<const std::uint8_t*>(bc->data());
  const std::size_t n = first.columns.size();
  const int nb = int(scene.bodies.size());
  auto find = [&](const std::string& name, const char* option) {
    const int b = scene.body_index(name);
    if (b < 0) throw InputError(option, "no body named '" + name + "' in the scene");
    return b;
  };
  // Projectile: the fastest body; target: the first body at rest.
  int proj = opt_.projectile.empty() ? -1 : find(opt_.projectile, "--projectile");
  int target = opt_.target.empty() ? -1 : find(opt_.target, "--target");
  if (proj < 0) {
    double best = 0;
    for (int b = 0; b < nb; ++b)
      if (scene.bodies[b].velocity.norm() > best) best = scene.bodies[b].velocity.norm(), proj = b;
    if (proj < 0) throw InputError("debris", "no body moves at t = 0: give --projectile");
  }
  if (target < 0) {
    for (int b = 0; b < nb && target < 0; ++b)
      if (b != proj && scene.bodies[b].velocity.norm() == 0) target = b;
    if (target < 0) throw InputError("debris", "no body is at rest at t = 0: give --target");
  }
  const Vec3 vp = scene.bodies[proj].velocity;
  axis_ = opt_.axis;
  if (axis_ < 0) {
    axis_ = 0;
    for (int a = 1; a < dim_; ++a)
      if (std::abs(vp[a]) > std::abs(vp[axis_])) axis_ = a;
  }
  direction_ = vp[axis_] < 0 ? -1 : 1;
  // The projectile's initial centre, and the target's rear face (surface).
  double far = -1e300;
  std::size_t np = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (body[i] == proj) {
      for (int a = 0; a < dim_; ++a) point_[a] += x[i * dim_ + a];
      ++np;
    }
    if (body[i] == target) far = std::max(far, direction_ * x[i * dim_ + axis_]);
  }
  if (np == 0 || far < -1e299) throw InputError("debris", "the first frame lacks the projectile or the target");
  point_ /= double(np);
  const double spacing = scene.grid.cell_size / scene.bodies[target].particles_per_cell;
  plane_ = opt_.plane ? *opt_.plane : direction_ * (far + 0.5 * spacing);
  (void)v;
}

DebrisResult DebrisMeter::measure(const Frame& frame) const {
  const auto* x = reinterpret_cast<const double*>(frame.columns.at(col::x).data());
  const std::size_t n = frame.columns.size();
  DebrisResult r;
  r.time = frame.time;
  r.axis = axis_;
  r.direction = direction_;
  r.plane = plane_;
  r.axis_point = point_;
  r.total = n;
  r.percentile = opt_.percentile;
  std::vector<double> front, width;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = direction_ * (x[i * dim_ + axis_] - plane_);
    if (!(d > 0)) continue;
    double r2 = 0;
    for (int a = 0; a < dim_; ++a)
      if (a != axis_) r2 += (x[i * dim_ + a] - point_[a]) * (x[i * dim_ + a] - point_[a]);
    front.push_back(d);
    width.push_back(2 * std::sqrt(r2));
  }
  r.cloud = front.size();
  if (front.empty()) return r;
  r.front_max = *std::max_element(front.begin(), front.end());
  r.width_max = *std::max_element(width.begin(), width.end());
  r.front_p99 = percentile(front, 99);
  r.front_p995 = percentile(front, 99.5);
  r.front_p999 = percentile(front, 99.9);
  r.width_p99 = percentile(width, 99);
  r.width_p995 = percentile(width, 99.5);
  r.width_p999 = percentile(width, 99.9);
  r.front = percentile(front, opt_.percentile);
  r.width = percentile(width, opt_.percentile);
  return r;
}

}  // namespace mpm
