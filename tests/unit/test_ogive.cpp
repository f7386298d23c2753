// The ogive primitive: its closed-form volume, surface and extent against quadrature and brute
// force, and a placed, voxelised ogive (V6's projectile) against them: volume, nose tip, shank.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "mpm/core/error.hpp"
#include "mpm/grid/lattice.hpp"
#include "mpm/prep/ogive.hpp"
#include "mpm/prep/region.hpp"
#include "mpm/prep/voxelise.hpp"

using namespace mpm;

namespace {

constexpr double kPi = std::numbers::pi;

/// Composite Simpson's rule of f over [a, b] with n (even) intervals.
template <class F>
double simpson(F f, double a, double b, int n) {
  const double h = (b - a) / n;
  double s = f(a) + f(b);
  for (int i = 1; i < n; ++i) s += (i % 2 ? 4 : 2) * f(a + i * h);
  return s * h / 3;
}

/// V6's projectile (Piekutowski et al. 1996): 12.9 mm diameter, 88.9 mm long, CRH 3.
Ogive v6_ogive() {
  return Ogive(0.5 * 12.9e-3, 88.9e-3, 3.0);
}

BodySpec ogive_body(double R, double length, double crh) {
  BodySpec b;
  b.name = "rod";
  b.material = 0;
  b.shape = ShapeKind::Ogive;
  b.radius = R;
  b.length = length;
  b.crh = crh;
  b.particles_per_cell = 2;
  b.loc.line = 10;
  b.loc.key = "bodies.rod";
  return b;
}

Scene scene_around(double h, const Vec3& lo, const Vec3& hi) {
  Scene s;
  s.source = "scene.toml";
  s.dimension = 3;
  MaterialSpec steel;
  steel.name = "steel";
  steel.density = 7850;
  s.materials = {steel};
  s.grid.cell_size = h;
  s.grid.domain_given = true;
  s.grid.domain_min = lo;
  s.grid.domain_max = hi;
  s.grid.loc.line = 3;
  return s;
}

Mat3 rotation(const Vec3& deg) {
  const double k = kPi / 180;
  return (Eigen::AngleAxisd(k * deg.z(), Vec3::UnitZ()) *
          Eigen::AngleAxisd(k * deg.y(), Vec3::UnitY()) *
          Eigen::AngleAxisd(k * deg.x(), Vec3::UnitX()))
      .toRotationMatrix();
}

/// A body placed in a scene and filled with particles: its region, the particles and the report.
struct Filled {
  std::unique_ptr<Region> region;
  ColumnStore store;
  std::vector<BodyReport> report;
};

Filled fill(Scene s, const BodySpec& b) {
  s.bodies = {b};
  Filled f;
  f.region = make_region(b, s);
  f.store = voxelise(s, make_lattice(s), f.report);
  return f;
}

std::string input_error(const BodySpec& b, const Scene& s) {
  try {
    make_region(b, s);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

}  // namespace

TEST(Ogive, ClosedFormVolumeAndAreaMatchQuadrature) {
  // The nose's profile is smooth on [L_shank, length] (C1 where it meets the shank), so
  // Simpson's rule on 2e4 intervals of each part is exact to ~1e-14 relative; 1e-10 leaves
  // room for round-off only.
  for (const double crh : {0.5, 1.0, 3.0, 7.5}) {
    SCOPED_TRACE("crh " + std::to_string(crh));
    const double R = 6.45e-3;
    const double nose = Ogive::nose_length(R, crh);
    const Ogive o(R, nose + 0.05, crh);
    EXPECT_NEAR(o.L_nose, R * std::sqrt(4 * crh - 1), 1e-15);
    const auto area = [&](double z) { return kPi * std::pow(o.radius_at(z), 2); };
    const double v = simpson(area, 0, o.L_shank, 20000) + simpson(area, o.L_shank, o.length, 20000);
    EXPECT_NEAR(o.volume() / v, 1.0, 1e-10);
    // Surface: base disk + 2 pi int r sqrt(1 + r'^2) dz; on the arc r' = -(z - L_shank) / (r + a)
    // so r sqrt(1 + r'^2) = r rho / (r + a).
    const auto band = [&](double z) {
      const double r = o.radius_at(z);
      return 2 * kPi * r * o.rho / (r + o.a);
    };
    const double s =
        kPi * R * R + 2 * kPi * R * o.L_shank + simpson(band, o.L_shank, o.length, 20000);
    EXPECT_NEAR(o.surface_area() / s, 1.0, 1e-10);
  }
  // crh = 1/2 is a hemisphere on the shank: 2/3 pi R^3 exactly.
  const Ogive hemi(0.01, 0.01, 0.5);
  EXPECT_NEAR(hemi.volume(), 2.0 / 3.0 * kPi * 1e-6, 1e-18);
  EXPECT_NEAR(hemi.surface_area(), 3 * kPi * 1e-4, 1e-16);
}

TEST(Ogive, SupportFunctionIsTheMaximumOverTheProfile) {
  // Brute force: w . u over 2e5 profile points (the best azimuth, q r) of the shank's ends, the
  // nose and the tip; its sampling error is below |w| (dz^2 / rho) ~ 1e-12 m for these sizes.
  const Ogive o = v6_ogive();
  const int n = 200000;
  for (const Vec3& w : {Vec3(0, 0, 1), Vec3(0, 0, -1), Vec3(1, 0, 0), Vec3(0.3, -0.2, 0.9),
                        Vec3(0.8, 0.1, 0.35), Vec3(-0.5, 0.5, -0.2), Vec3(2.0, 0, 0.4)}) {
    const double q = std::hypot(w.x(), w.y());
    double best = -1e300;
    for (int i = 0; i <= n; ++i) {
      const double z = o.length * i / n;
      best = std::max(best, w.z() * z + q * o.radius_at(z));
    }
    EXPECT_NEAR(o.support(w), best, 1e-9) << w.transpose();
    EXPECT_GE(o.support(w), best - 1e-15) << w.transpose();
  }
}

TEST(Ogive, InsideTestTipAndShankRadius) {
  const Ogive o = v6_ogive();
  const double e = 1e-9;
  EXPECT_TRUE(o.contains(Vec3(0, 0, o.length - e)));
  EXPECT_FALSE(o.contains(Vec3(0, 0, o.length + e)));
  EXPECT_FALSE(o.contains(Vec3(0, 0, -e)));
  for (const double phi : {0.0, 1.0, 2.5, 4.0}) {
    const Vec3 dir(std::cos(phi), std::sin(phi), 0);
    for (const double z : {e, 0.5 * o.L_shank, o.L_shank - e}) {
      EXPECT_TRUE(o.contains((o.R - e) * dir + Vec3(0, 0, z)));
      EXPECT_FALSE(o.contains((o.R + e) * dir + Vec3(0, 0, z)));
    }
    // Half-way along the nose the radius is the arc's.
    const double z = o.L_shank + 0.5 * o.L_nose, r = o.radius_at(z);
    EXPECT_NEAR(r, std::sqrt(o.rho * o.rho - 0.25 * o.L_nose * o.L_nose) - o.a, 1e-15);
    EXPECT_TRUE(o.contains((r - e) * dir + Vec3(0, 0, z)));
    EXPECT_FALSE(o.contains((r + e) * dir + Vec3(0, 0, z)));
  }
}

TEST(Ogive, PlacedAndVoxelisedLikeThePrimitives) {
  // V6's projectile, rotated and translated off the lattice.
  const double h = 0.8e-3, s_p = h / 2;  // particle spacing 0.4 mm: 32 across the shank
  Scene s = scene_around(h, Vec3(-0.06, -0.06, -0.06), Vec3(0.08, 0.06, 0.08));
  BodySpec b = ogive_body(0.5 * 12.9e-3, 88.9e-3, 3.0);
  b.rotate_deg = Vec3(12, 63, -21);
  b.translate = Vec3(-0.031, 0.0017, -0.0123);
  const Ogive o(b.radius, b.length, b.crh);
  const auto [region, store, report] = fill(s, b);
  EXPECT_NEAR(region->volume() / o.volume(), 1.0, 1e-14);
  ASSERT_EQ(report.size(), 1u);
  EXPECT_NEAR(report[0].exact_mass, 7850 * o.volume(), 1e-9);

  // Volume: count x s^3 - V is the sum over the points whose cube straddles the surface (those
  // within sqrt(3)/2 s of it, about N = sqrt(3) S / s^2 of them) of 1{inside} - (the share of
  // the cube inside), each within +-1/2. Placed off the lattice these terms have mean zero, so
  // the error's standard deviation is at most s^3 sqrt(N) / 2; allow 4 of them (0.25% here).
  const double n_shell = std::sqrt(3.0) * o.surface_area() / (s_p * s_p);
  const double tol = 4 * std::pow(s_p, 3) * std::sqrt(n_shell) / 2;
  const double v_count = store.size() * std::pow(s_p, 3);
  EXPECT_NEAR(v_count, o.volume(), tol) << "relative tolerance " << tol / o.volume();
  std::printf("ogive volume: lattice %.6g mm^3, exact %.6g mm^3, error %.3g%% (tolerance %.3g%%)\n",
              v_count * 1e9, o.volume() * 1e9, 100 * (v_count / o.volume() - 1),
              100 * tol / o.volume());
  EXPECT_NEAR(report[0].mass / report[0].exact_mass, 1.0, tol / o.volume());

  // Every particle inside, and the extreme ones close to the nose tip and the shank's surface.
  const Mat3 R = rotation(b.rotate_deg);
  const Vec3 axis = R * Vec3::UnitZ(), tip = b.translate + b.length * axis;
  const double* x = reinterpret_cast<const double*>(store.at("x").data());
  double reach = -1e300, shank_r = 0;
  Vec3 lo, hi, plo = Vec3::Constant(1e300), phi = -plo;
  region->bounds(lo, hi);
  for (std::size_t p = 0; p < store.size(); ++p) {
    const Vec3 xp(x[3 * p], x[3 * p + 1], x[3 * p + 2]);
    const Vec3 u = R.transpose() * (xp - b.translate);
    ASSERT_TRUE(o.contains(u)) << "particle " << p;
    reach = std::max(reach, u.z());
    if (u.z() < o.L_shank) shank_r = std::max(shank_r, u.head<2>().norm());
    plo = plo.cwiseMin(xp);
    phi = phi.cwiseMax(xp);
  }
  // The nose holds the cone from its tip to the shank's end (it is convex), of half-angle
  // beta = atan(R / L_nose); a ball of radius sqrt(3)/2 s, which always holds a lattice point,
  // fits in it at (1 + sin beta) / sin beta sqrt(3)/2 s from the tip.
  const double sb = std::sin(std::atan(o.R / o.L_nose));
  EXPECT_LE(reach, b.length);
  EXPECT_GE(reach, b.length - (1 + sb) / sb * std::sqrt(3.0) / 2 * s_p);
  EXPECT_NEAR((tip - b.translate).norm(), b.length, 1e-15);
  // The shank's outermost particle: within the diameter of such a ball of the surface.
  EXPECT_LE(shank_r, o.R);
  EXPECT_GE(shank_r, o.R - std::sqrt(3.0) * s_p);
  // The region's box holds the particles and is tight (the lattice reaches within 2 s of it).
  EXPECT_TRUE((plo.array() >= lo.array()).all() && (phi.array() <= hi.array()).all());
  EXPECT_LT((plo - lo).maxCoeff(), 2 * s_p);
  EXPECT_LT((hi - phi).maxCoeff(), 2 * s_p);
}

TEST(Ogive, BadGeometryIsRefusedAtItsKey) {
  Scene s = scene_around(1e-3, Vec3(-0.1, -0.1, -0.1), Vec3(0.1, 0.1, 0.1));
  BodySpec b = ogive_body(6.45e-3, 88.9e-3, 0.4);
  s.bodies = {b};
  EXPECT_EQ(input_error(b, s).substr(0, 50), "scene.toml:10: bodies.rod.crh: the nose's arc radi");
  b.crh = 3;
  b.length = 0.02;  // the nose alone is 6.45 sqrt(11) = 21.39 mm
  const std::string e = input_error(b, s);
  EXPECT_EQ(e.substr(0, 33), "scene.toml:10: bodies.rod.length:");
  EXPECT_NE(e.find("at least its nose's, 21.3922 mm for crh 3"), std::string::npos) << e;
}

// 2D scenes take the ogive's axial section: in plane strain a wedge-nosed plate, in axisymmetry
// the section revolved about the axis (the projectile itself).

TEST(Ogive, SectionAreaAndPerimeterMatchQuadrature) {
  // Area: int 2 r(z) dz over the length. Perimeter: base, the shank's two sides and the two arcs,
  // each arc's length from a fine polyline through the profile.
  for (double crh : {0.5, 1.0, 3.0, 7.5}) {
    const double R = 0.0127, nose = Ogive::nose_length(R, crh);
    const Ogive o(R, nose + 0.05, crh);
    // The substitution z = L_shank + L sin(t) takes out the arc's square-root end at the tip of a
    // hemisphere (its slope is infinite there).
    const double area = simpson([&](double z) { return 2 * o.radius_at(z); }, 0, o.L_shank, 2) +
                        simpson(
                            [&](double t) {
                              const double z = o.L_shank + o.L_nose * std::sin(t);
                              return 2 * o.radius_at(z) * o.L_nose * std::cos(t);
                            },
                            0, kPi / 2, 20000);
    EXPECT_NEAR(o.section_area() / area, 1.0, 1e-10) << "crh " << crh;
    // The arc from the profile's polyline through z = L_shank + L sin(t): the chords err by
    // about the arc's length times (its angle / n)^2 / 24.
    double arc = 0;
    const int n = 100000;
    for (int i = 0; i < n; ++i) {
      const double z0 = o.L_shank + o.L_nose * std::sin(0.5 * kPi * i / n);
      const double z1 = o.L_shank + o.L_nose * std::sin(0.5 * kPi * (i + 1) / n);
      arc += std::hypot(z1 - z0, o.radius_at(z1) - o.radius_at(z0));
    }
    EXPECT_NEAR(o.section_perimeter(), 2 * R + 2 * o.L_shank + 2 * arc, 1e-9 * o.L_nose)
        << "crh " << crh;
  }
  // A hemispherical nose on a zero-length shank is a half-disk.
  const Ogive hemi(0.01, 0.01, 0.5);
  EXPECT_NEAR(hemi.section_area(), 0.5 * kPi * 1e-4, 1e-16);
  EXPECT_NEAR(hemi.section_perimeter(), 0.02 + kPi * 0.01, 1e-15);
}

TEST(Ogive, PlaneSectionVoxelisedInTwoDimensions) {
  // V6's projectile's section, rotated 37 degrees and off the lattice, in plane strain: its area
  // from the particles against the exact one, every particle inside, and the box tight.
  const double h = 0.4e-3, s_p = h / 2;
  Scene s = scene_around(h, Vec3(-0.06, -0.06, 0), Vec3(0.08, 0.08, 0));
  s.dimension = 2;
  BodySpec b = ogive_body(0.5 * 12.9e-3, 88.9e-3, 3.0);
  b.rotate_deg = Vec3(0, 0, 37);
  b.translate = Vec3(0.0131, -0.0217, 0);
  const Ogive o(b.radius, b.length, b.crh);
  const auto [region, store, report] = fill(s, b);
  EXPECT_NEAR(region->volume() / o.section_area(), 1.0, 1e-14);
  ASSERT_EQ(report.size(), 1u);
  EXPECT_NEAR(report[0].exact_mass / (7850 * o.section_area()), 1.0, 1e-14);
  // count x s^2 - A sums, over the points whose square straddles the boundary (within s / sqrt(2)
  // of it: about N = sqrt(2) P / s of them), terms within +-1/2 of mean zero off the lattice: the
  // error's standard deviation is at most s^2 sqrt(N) / 2; allow 4 of them (0.3% here).
  const double n_shell = std::sqrt(2.0) * o.section_perimeter() / s_p;
  const double tol = 4 * s_p * s_p * std::sqrt(n_shell) / 2;
  const double a_count = store.size() * s_p * s_p;
  EXPECT_NEAR(a_count, o.section_area(), tol) << "relative tolerance " << tol / o.section_area();
  std::printf(
      "ogive section: lattice %.6g mm^2, exact %.6g mm^2, error %.3g%% (tolerance %.3g%%)\n",
      a_count * 1e6, o.section_area() * 1e6, 100 * (a_count / o.section_area() - 1),
      100 * tol / o.section_area());
  EXPECT_NEAR(report[0].mass / report[0].exact_mass, 1.0, tol / o.section_area());

  const Mat3 R = rotation(b.rotate_deg);
  const int dim = store.at("x").info().components;
  const double* x = reinterpret_cast<const double*>(store.at("x").data());
  Vec3 lo, hi, plo = Vec3::Constant(1e300), phi = -plo;
  region->bounds(lo, hi);
  double reach = -1e300;
  for (std::size_t p = 0; p < store.size(); ++p) {
    const Vec3 xp(x[dim * p], x[dim * p + 1], 0);
    const Vec3 u = R.transpose() * (xp - b.translate);  // the section's local (x, y)
    ASSERT_TRUE(o.contains(Vec3(u.x(), 0, u.y()))) << "particle " << p;
    reach = std::max(reach, u.y());
    plo = plo.cwiseMin(xp);
    phi = phi.cwiseMax(xp);
  }
  EXPECT_LE(reach, b.length);
  EXPECT_GE(reach, b.length - 3 * s_p / std::sin(std::atan(o.R / o.L_nose)));
  for (int a = 0; a < 2; ++a) {
    EXPECT_GE(plo[a], lo[a]);
    EXPECT_LE(phi[a], hi[a]);
    EXPECT_LT(plo[a] - lo[a], 2 * s_p) << a;
    EXPECT_LT(hi[a] - phi[a], 2 * s_p) << a;
  }
}

TEST(Ogive, AxisymmetricSectionIsTheProjectile) {
  // Hanchak's projectile (V5) nose down on the axis: the exact mass per radian is rho V / (2 pi)
  // and the particles' (rho s^2 x_p each) converge to it. The lattice tiles the shank exactly (R
  // is 32 spacings and the base lies on a lattice line), so only the nose's points straddling the
  // arc err: about N = sqrt(2) l / s of them (l the arc), each by at most s^2 R / 2 with mean
  // zero; allow 4 standard deviations.
  const double R = 12.7e-3, s_p = R / 32, h = 2 * s_p;
  Scene s = scene_around(h, Vec3(0, -0.2, 0), Vec3(64 * h, 0.2, 0));
  s.dimension = 2;
  s.axisymmetric = true;
  BodySpec b = ogive_body(R, 143.7e-3, 3.0);
  b.rotate_deg = Vec3(0, 0, 180);
  b.translate = Vec3(0, -0.2 + 400 * s_p, 0);  // the base on a lattice line
  const Ogive o(b.radius, b.length, b.crh);
  const auto report = fill(s, b).report;
  ASSERT_EQ(report.size(), 1u);
  const double exact = 7850 * o.volume() / (2 * kPi);
  EXPECT_NEAR(report[0].exact_mass / exact, 1.0, 1e-14);
  const double arc = o.rho * std::asin(o.L_nose / o.rho);
  const double tol = 4 * s_p * s_p * R / 2 * std::sqrt(std::sqrt(2.0) * arc / s_p) * 7850 / exact;
  EXPECT_NEAR(report[0].mass / exact, 1.0, tol);
  std::printf(
      "axisymmetric ogive: particles' mass %.6g g / rad, exact %.6g, error %.3g%% "
      "(tolerance %.3g%%); whole %.6g g\n",
      report[0].mass * 1e3, exact * 1e3, 100 * (report[0].mass / exact - 1), 100 * tol,
      2 * kPi * exact * 1e3);
  // Scaled by 2 radially and 1.5 along the axis: s_x^2 s_y times the volume.
  b.scale = Vec3(2, 1.5, 1);
  EXPECT_NEAR(make_region(b, s)->revolved_volume() / (6 * o.volume() / (2 * kPi)), 1.0, 1e-14);
}

TEST(Ogive, AxisymmetricOgiveOffTheAxisIsRefused) {
  Scene s = scene_around(1e-3, Vec3(0, -0.2, 0), Vec3(0.1, 0.2, 0));
  s.dimension = 2;
  s.axisymmetric = true;
  BodySpec b = ogive_body(6.45e-3, 88.9e-3, 3.0);
  b.translate = Vec3(0.01, 0, 0);
  std::string e = input_error(b, s);
  EXPECT_EQ(e.substr(0, 37), "scene.toml:10: bodies.rod.translate: ") << e;
  EXPECT_NE(e.find("on the axis, x = 0 (got x = 10 mm)"), std::string::npos) << e;
  b.translate = Vec3(0, 0, 0);
  b.rotate_deg = Vec3(0, 0, 90);
  e = input_error(b, s);
  EXPECT_EQ(e.substr(0, 34), "scene.toml:10: bodies.rod.rotate: ") << e;
  b.rotate_deg = Vec3(0, 0, 180);
  EXPECT_EQ(input_error(b, s), "(no InputError)");
  s.axisymmetric = false;  // plane strain: anywhere, any angle
  b.translate = Vec3(0.01, 0, 0);
  b.rotate_deg = Vec3(0, 0, 90);
  EXPECT_EQ(input_error(b, s), "(no InputError)");
}
