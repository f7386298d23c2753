#include "mpm/post/post.hpp"

#include <algorithm>
#include <cmath>

#include "mpm/core/error.hpp"
#include "mpm/post/calipers.hpp"
#include "mpm/post/impact.hpp"
#include "mpm/scene/particles.hpp"

namespace mpm {

TaylorMeter::TaylorMeter(const Scene& scene, const TaylorOptions& options)
    : scene_(scene), opt_(options), symmetry_(options.symmetry.value_or(scene_symmetry(scene))) {
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
  TaylorResult r;
  r.time = frame.time;
  r.symmetry = symmetry_;
  const BodySpec& spec = scene_.bodies[body_];
  r.spacing = spec.spacing(scene_.grid.cell_size);
  r.measure = opt_.surface ? "surface" : "centres";
  // The whole bar: the body's particles and their mirror images.
  const WholeBody whole = unfold(frame, d, symmetry_, {body_});
  const std::vector<Vec3>& x = whole.x;
  r.particles = whole.particles;
  if (r.particles == 0)
    throw InputError("taylor", "body '" + spec.name + "' has no particles in the frame at t = " +
                                   std::to_string(frame.time) + " s");

  // Bounding box and mass centre of the bar.
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300), centre = Vec3::Zero();
  double mass = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    lo = lo.cwiseMin(x[i]);
    hi = hi.cwiseMax(x[i]);
    centre += whole.m[i] * x[i];
    mass += whole.m[i];
  }
  centre /= mass;

  // Axis: as given, else the longest extent of the body.
  r.axis = opt_.axis;
  if (scene_.axisymmetric) {  // x is the radius: the bar's axis is the symmetry axis y
    if (r.axis == 0)
      throw InputError("--axis", "an axisymmetric scene's bar stands along y (x is the radius)");
    r.axis = 1;
  }
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
    if (at_min && (!at_max || lo[ax] - dmin[ax] <= dmax[ax] - hi[ax]))
      r.wall = dmin[ax];
    else
      r.wall = dmax[ax];
  }

  double L = 0, R = 0;
  std::vector<double> u, w;  // the particles' coordinates across the axis (3D)
  if (d == 3) u.reserve(x.size()), w.reserve(x.size());
  const int a1 = (ax + 1) % 3, a2 = (ax + 2) % 3;
  const int lat = d == 2 ? 1 - ax : -1;  // 2D: the one coordinate across the axis
  for (const Vec3& p : x) {
    L = std::max(L, std::abs(p[ax] - r.wall));
    double r2 = 0;
    for (int a = 0; a < d; ++a)
      if (a != ax) r2 += (p[a] - centre[a]) * (p[a] - centre[a]);
    R = std::max(R, std::sqrt(r2));
    if (d == 3) u.push_back(p[a1]), w.push_back(p[a2]);
  }
  const double add = opt_.surface ? r.spacing : 0.0;
  r.L = L + 0.5 * add;
  if (d == 3) {
    const Calipers c = caliper_widths(u, w);
    r.D = c.mean + add, r.D_min = c.min + add, r.D_max = c.max + add;
    r.D_radius = 2 * R + add;
  } else if (scene_.axisymmetric) {
    // x is the radius (never negative): the foot is a disc twice its largest radius across.
    r.D = r.D_min = r.D_max = r.D_radius = 2 * hi[lat] + add;
  } else {
    r.D = r.D_min = r.D_max = hi[lat] - lo[lat] + add;
    r.D_radius = 2 * R + add;
  }
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

/// p-th percentile (0..100) of values weighted by w (> 0): the smallest value whose cumulative
/// weight, in ascending order of the values, reaches p / 100 of the total. For unequal weights:
/// with equal ones the nearest-rank percentile above is the same and exact (sums of many equal
/// weights round, and would move a rank that falls on a whole number).
double percentile(const std::vector<double>& v, const std::vector<double>& w, double p) {
  if (v.empty()) return 0;
  std::vector<std::size_t> order(v.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return v[a] < v[b]; });
  if (p <= 0) return v[order.front()];
  long double total = 0;
  for (const double x : w) total += x;
  const long double target = (long double)(p / 100.0) * total * (1 - 1e-12L);
  long double sum = 0;
  for (const std::size_t i : order) {
    sum += w[i];
    if (sum >= target) return v[i];
  }
  return v[order.back()];
}

}  // namespace

std::vector<std::size_t> fragment_sizes(const std::vector<Vec3>& points, double link) {
  const std::size_t n = points.size();
  std::vector<std::size_t> size(n, 1);
  if (n == 0) return size;
  if (!(link > 0)) throw InputError("--link", "expected a positive linking length");
  // Union-find over the points, by size, with path halving.
  std::vector<std::size_t> parent(n);
  for (std::size_t i = 0; i < n; ++i) parent[i] = i;
  auto root = [&](std::size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  auto join = [&](std::size_t a, std::size_t b) {
    a = root(a), b = root(b);
    if (a == b) return;
    if (size[a] < size[b]) std::swap(a, b);
    parent[b] = a;
    size[a] += size[b];
  };
  // Bin the points in cubes of side `link`: linked points lie in the same or adjacent cubes.
  Vec3 lo = points[0];
  for (const Vec3& p : points) lo = lo.cwiseMin(p);
  constexpr std::int64_t kSide = 1 << 20;
  auto cell = [&](const Vec3& p, int a) { return std::int64_t(std::floor((p[a] - lo[a]) / link)); };
  auto key = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
    return std::uint64_t((i * kSide + j) * kSide + k);
  };
  std::vector<std::pair<std::uint64_t, std::size_t>> bins(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::int64_t c[3] = {cell(points[i], 0), cell(points[i], 1), cell(points[i], 2)};
    if (c[0] >= kSide || c[1] >= kSide || c[2] >= kSide)
      throw InputError("--link",
                       "the cloud spans more than 2^20 linking lengths: give a longer --link");
    bins[i] = {key(c[0], c[1], c[2]), i};
  }
  std::sort(bins.begin(), bins.end());
  const double link2 = link * link;
  struct ByKey {
    bool operator()(const std::pair<std::uint64_t, std::size_t>& b, std::uint64_t k) const {
      return b.first < k;
    }
    bool operator()(std::uint64_t k, const std::pair<std::uint64_t, std::size_t>& b) const {
      return k < b.first;
    }
  };
  auto range = [&](std::uint64_t k) {
    return std::equal_range(bins.begin(), bins.end(), k, ByKey{});
  };
  // Each bin against itself and its 13 neighbours that come after it.
  for (auto b = bins.begin(); b != bins.end();) {
    const std::size_t i0 = b->second;
    const std::int64_t c[3] = {cell(points[i0], 0), cell(points[i0], 1), cell(points[i0], 2)};
    const auto e = range(b->first).second;
    for (auto p = b; p != e; ++p)
      for (auto q = p + 1; q != e; ++q)
        if ((points[p->second] - points[q->second]).squaredNorm() < link2)
          join(p->second, q->second);
    for (int di = -1; di <= 1; ++di)
      for (int dj = -1; dj <= 1; ++dj)
        for (int dk = -1; dk <= 1; ++dk) {
          const int order = di * 9 + dj * 3 + dk;
          if (order <= 0) continue;  // half of the 26 neighbours: each pair of bins once
          const std::int64_t ni = c[0] + di, nj = c[1] + dj, nk = c[2] + dk;
          if (ni < 0 || nj < 0 || nk < 0) continue;
          const auto [f, l] = range(key(ni, nj, nk));
          for (auto p = b; p != e; ++p)
            for (auto q = f; q != l; ++q)
              if ((points[p->second] - points[q->second]).squaredNorm() < link2)
                join(p->second, q->second);
        }
    b = e;
  }
  std::vector<std::size_t> out(n);
  for (std::size_t i = 0; i < n; ++i) out[i] = size[root(i)];
  return out;
}

DebrisMeter::DebrisMeter(const Scene& scene, const Frame& first, const DebrisOptions& options)
    : opt_(options), symmetry_(options.symmetry.value_or(scene_symmetry(scene))) {
  const Impact im =
      find_impact(scene, first, symmetry_, {opt_.axis, opt_.projectile, opt_.target}, "debris");
  dim_ = im.dimension;
  axisymmetric_ = scene.axisymmetric;
  axis_ = im.axis;
  direction_ = im.direction;
  point_ = im.point;
  // The reference plane: the whole target's rear face (surface: centres + half a spacing).
  const double spacing = scene.bodies[im.target].spacing(scene.grid.cell_size);
  plane_ = opt_.plane ? *opt_.plane : im.direction * (im.rear + 0.5 * spacing);
  // The face the front is measured from: the rear face, or the struck face (surface).
  face_plane_ =
      opt_.face == DebrisFace::Impact ? im.direction * (im.front - 0.5 * spacing) : plane_;
  link_ = opt_.link > 0 ? opt_.link : scene.grid.cell_size;
  if (opt_.min_fragment < 1) throw InputError("--min-fragment", "expected at least 1 particle");
}

DebrisResult DebrisMeter::measure(const Frame& frame) const {
  const WholeBody whole = unfold(frame, dim_, symmetry_, {});
  DebrisResult r;
  r.time = frame.time;
  r.axis = axis_;
  r.direction = direction_;
  r.plane = plane_;
  r.face = opt_.face;
  r.face_plane = face_plane_;
  r.axis_point = point_;
  r.total = whole.particles;
  r.percentile = opt_.percentile;
  r.link = link_;
  r.min_fragment = opt_.min_fragment;
  r.symmetry = symmetry_;
  if (axisymmetric_ && !frame.columns.find(col::m))
    throw InputError("debris", "an axisymmetric frame needs the column 'm' (the rings' masses)");
  std::vector<double> front, width, mass;
  std::vector<Vec3> cloud;
  for (std::size_t i = 0; i < whole.x.size(); ++i) {
    const Vec3& p = whole.x[i];
    const double d = direction_ * (p[axis_] - plane_);
    if (!(d > 0)) continue;
    mass.push_back(whole.m[i]);
    double r2 = 0;
    for (int a = 0; a < dim_; ++a)
      if (a != axis_) r2 += (p[a] - point_[a]) * (p[a] - point_[a]);
    front.push_back(direction_ * (p[axis_] - face_plane_));
    width.push_back(2 * std::sqrt(r2));
    cloud.push_back(p);
  }
  r.cloud = front.size();
  if (front.empty()) return r;
  // Fragments; only the particles of fragments of at least min_fragment particles count.
  const std::vector<std::size_t> size = fragment_sizes(cloud, link_);
  std::size_t kept = 0;
  for (std::size_t i = 0; i < size.size(); ++i) {
    r.largest = std::max(r.largest, size[i]);
    if (size[i] == 1) ++r.singles;
    if (size[i] >= opt_.min_fragment)
      front[kept] = front[i], width[kept] = width[i], mass[kept] = mass[i], ++kept;
  }
  double fragments = 0;  // a fragment of k particles: k particles of 1 / k each
  for (const std::size_t k : size) fragments += 1.0 / double(k);
  r.fragments = std::size_t(std::llround(fragments));
  front.resize(kept);
  width.resize(kept);
  mass.resize(kept);
  r.counted = kept;
  if (front.empty()) return r;
  r.by_mass = !std::all_of(mass.begin(), mass.end(), [&](double w) { return w == mass[0]; });
  r.front_max = *std::max_element(front.begin(), front.end());
  r.width_max = *std::max_element(width.begin(), width.end());
  const auto pct = [&](const std::vector<double>& v, double p) {
    return r.by_mass ? percentile(v, mass, p) : percentile(v, p);
  };
  r.front_p99 = pct(front, 99);
  r.front_p995 = pct(front, 99.5);
  r.front_p999 = pct(front, 99.9);
  r.width_p99 = pct(width, 99);
  r.width_p995 = pct(width, 99.5);
  r.width_p999 = pct(width, 99.9);
  r.front = pct(front, opt_.percentile);
  r.width = pct(width, opt_.percentile);
  return r;
}

}  // namespace mpm
