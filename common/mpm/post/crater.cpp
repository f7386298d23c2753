// Crater depth and diameter on the impact axis, and how deep each body went.
#include "mpm/post/crater.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "mpm/core/error.hpp"

namespace mpm {

namespace {

constexpr double kNone = std::numeric_limits<double>::infinity();

/// The whole target's particles as depth below the original front centres and radius from
/// the axis, m.
struct Section {
  std::vector<double> zeta, rho;
};

Section section(const WholeBody& target, const Impact& im) {
  Section s;
  s.zeta.reserve(target.x.size());
  s.rho.reserve(target.x.size());
  for (const Vec3& p : target.x) {
    s.zeta.push_back(im.direction * p[im.axis] - im.front);
    s.rho.push_back(im.radius(p));
  }
  return s;
}

}  // namespace

CraterMeter::CraterMeter(const Scene& scene, const Frame& first, const CraterOptions& options)
    : scene_(scene), symmetry_(options.symmetry.value_or(scene_symmetry(scene))) {
  impact_ = find_impact(scene, first, symmetry_, options.impact, "crater");
  spacing_ = scene.bodies[impact_.target].spacing(scene.grid.cell_size);
}

CraterResult CraterMeter::measure(const Frame& frame) const {
  const Impact& im = impact_;
  const double s = spacing_, T_c = im.rear - im.front;  // centres' thickness
  CraterResult r;
  r.time = frame.time;
  r.target = scene_.bodies[im.target].name;
  r.axis = im.axis;
  r.direction = im.direction;
  r.axis_point = im.point;
  r.spacing = s;
  r.surface = im.direction * (im.front - 0.5 * s);
  if (std::abs(r.surface) < 1e-9 * s) r.surface = 0;  // a face at 0 less round-off
  r.thickness = T_c + s;
  r.symmetry = symmetry_;
  const WholeBody target = unfold(frame, im.dimension, symmetry_, {im.target});
  r.particles = target.particles;
  const Section sec = section(target, im);
  const std::size_t n = sec.zeta.size();

  // Perforated: no target centre within a spacing of the axis through the thickness.
  r.perforated = true;
  for (std::size_t i = 0; i < n && r.perforated; ++i)
    if (sec.rho[i] < s && sec.zeta[i] >= -0.5 * s && sec.zeta[i] <= T_c + 0.5 * s)
      r.perforated = false;
  if (r.perforated) {
    // The hole: the narrowest of the layers one spacing thick through the original thickness.
    const int layers = int(std::lround(T_c / s)) + 1;
    std::vector<double> inner(std::size_t(layers), kNone);
    for (std::size_t i = 0; i < n; ++i) {
      const long j = std::lround(sec.zeta[i] / s);
      if (j >= 0 && j < layers) inner[j] = std::min(inner[j], sec.rho[i]);
    }
    const double narrowest = *std::min_element(inner.begin(), inner.end());
    r.depth = r.thickness;
    r.diameter = narrowest < kNone ? std::max(0.0, 2 * narrowest - s) : NAN;
  } else {
    // The crater's wall at the original surface: the innermost centre of the surface layer.
    double R_c = kNone;
    for (std::size_t i = 0; i < n; ++i)
      if (sec.zeta[i] >= -0.5 * s && sec.zeta[i] < 0.5 * s) R_c = std::min(R_c, sec.rho[i]);
    if (R_c == kNone) {
      r.depth = r.diameter = NAN;  // the surface layer is gone (moved off as a whole)
    } else {
      // The floor of each radial bin inside the wall: its shallowest centre below the surface
      // layer. Bins are two spacings wide: near the axis a bin one spacing wide holds a few
      // particles only (in a quarter model's whole, the four images of one column), and those
      // few are pushed aside and down by the projectile, below the floor their neighbours make.
      const double w = 2 * s;
      const std::size_t bins = std::max<std::size_t>(1, std::size_t(std::ceil(R_c / w)));
      std::vector<double> floor(bins, kNone);
      for (std::size_t i = 0; i < n; ++i)
        if (sec.rho[i] < R_c && sec.zeta[i] >= -0.5 * s) {
          const std::size_t k = std::min(bins - 1, std::size_t(sec.rho[i] / w));
          floor[k] = std::min(floor[k], sec.zeta[i]);
        }
      r.depth = 0;
      for (std::size_t k = 0; k < floor.size(); ++k) {
        if (floor[k] == kNone) continue;
        r.profile.push_back({(double(k) + 0.5) * w, floor[k]});
        r.depth = std::max(r.depth, floor[k]);
      }
      r.diameter = std::max(0.0, 2 * R_c - s);
    }
  }

  // Penetration: each body's deepest surface point below the target's original surface.
  for (int b = 0; b < int(scene_.bodies.size()); ++b) {
    if (b == im.target) continue;
    const WholeBody body = unfold(frame, im.dimension, symmetry_, {b});
    if (body.x.empty()) continue;
    double deepest = -kNone;
    for (const Vec3& p : body.x) deepest = std::max(deepest, im.direction * p[im.axis]);
    const double s_b = scene_.bodies[b].spacing(scene_.grid.cell_size);
    r.penetration.push_back({scene_.bodies[b].name, deepest - im.front + 0.5 * (s + s_b)});
  }
  return r;
}

}  // namespace mpm
