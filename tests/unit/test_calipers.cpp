// Caliper widths of planar point sets (the foot diameter of mpm-post taylor) against shapes
// whose widths are known exactly, and the Taylor meter on feet built by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>

#include "mpm/core/error.hpp"
#include "mpm/post/calipers.hpp"
#include "mpm/post/post.hpp"
#include "mpm/scene/particles.hpp"
#include "mpm/scene/scene.hpp"
#include "mpm/stream/stream.hpp"

namespace mpm {
namespace {

constexpr double kPi = std::numbers::pi;

// A filled square of side a turned by 30 degrees: mean width 4a / pi (perimeter / pi), the
// narrowest a (across a side), the widest a sqrt 2 (the diagonal). Interior points change none.
TEST(Calipers, FilledSquareAtAnyAngle) {
  const double a = 2.0, th = kPi / 6;
  std::vector<double> x, y;
  for (int i = 0; i <= 20; ++i)
    for (int j = 0; j <= 20; ++j) {
      const double u = a * i / 20 - 1, v = a * j / 20 - 1;
      x.push_back(u * std::cos(th) - v * std::sin(th) + 5);
      y.push_back(u * std::sin(th) + v * std::cos(th) - 3);
    }
  const Calipers c = caliper_widths(x, y);
  EXPECT_GE(c.hull_vertices,
            4u);  // edge points turned by 30 degrees may leave the line by round-off
  EXPECT_NEAR(c.mean, 4 * a / kPi, 1e-12);
  EXPECT_NEAR(c.min, a, 1e-12);
  EXPECT_NEAR(c.max, a * std::sqrt(2.0), 1e-12);
}

// A regular 12-gon inscribed in a circle of radius R: perimeter 24 R sin(pi / 12), widest 2R
// (opposite vertices), narrowest 2R cos(pi / 12) (opposite sides).
TEST(Calipers, RegularPolygon) {
  const double R = 3.0;
  const int n = 12;
  std::vector<double> x, y;
  for (int k = 0; k < n; ++k)
    x.push_back(R * std::cos(2 * kPi * k / n)), y.push_back(R * std::sin(2 * kPi * k / n));
  x.push_back(0), y.push_back(0);  // an interior point
  const Calipers c = caliper_widths(x, y);
  EXPECT_EQ(c.hull_vertices, std::size_t(n));
  EXPECT_NEAR(c.mean, 2 * n * R * std::sin(kPi / n) / kPi, 1e-12);
  EXPECT_NEAR(c.max, 2 * R, 1e-12);
  EXPECT_NEAR(c.min, 2 * R * std::cos(kPi / n), 1e-12);
}

// Degenerate sets: a segment's mean width is 2 length / pi, its narrowest 0; one point none.
TEST(Calipers, SegmentAndPoint) {
  const Calipers s = caliper_widths({0, 1, 2, 3}, {0, 1, 2, 3});
  EXPECT_NEAR(s.max, 3 * std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(s.mean, 2 * 3 * std::sqrt(2.0) / kPi, 1e-12);
  EXPECT_EQ(s.min, 0.0);
  const Calipers p = caliper_widths({1}, {1});
  EXPECT_EQ(p.mean, 0.0);
  EXPECT_EQ(p.max, 0.0);
}

// A bar standing on the wall z = 0 with a square foot (side a, as a Cartesian grid can leave
// it) under a round shank: D is the mean caliper width 4a / pi, D_min a, D_max and D_radius
// the diagonal a sqrt 2; L is the height of the top particle. --surface adds a spacing.
Scene bar_scene(int dimension, bool axisymmetric) {
  Scene s;
  s.dimension = dimension;
  s.axisymmetric = axisymmetric;
  s.grid.cell_size = 2e-3;
  BodySpec bar;
  bar.name = "bar";
  bar.particles_per_cell = 2;
  s.bodies = {bar};
  s.boundary.face[dimension == 3 ? 4 : 2] = BoundaryType::Fixed;
  return s;
}

Frame bar_frame(const std::vector<double>& xs, int d) {
  Frame f;
  f.time = 80e-6;
  f.columns.add({col::x, ScalarType::F64, d, "m"});
  f.columns.add({col::body, ScalarType::U8, 1, "-"});
  const std::size_t n = xs.size() / std::size_t(d);
  f.columns.resize(n);
  auto* x = reinterpret_cast<double*>(f.columns.find(col::x)->data());
  for (std::size_t i = 0; i < xs.size(); ++i) x[i] = xs[i];
  auto* b = f.columns.get<std::uint8_t>(col::body);
  for (std::size_t i = 0; i < n; ++i) b[i] = 0;
  return f;
}

TEST(TaylorMeter, SquareFootGivesItsMeanCaliperWidth) {
  const double a = 12e-3, s = 1e-3;
  std::vector<double> xs;
  for (int i = 0; i <= 12; ++i)  // the foot: z = 0.5 mm, a 13 x 13 lattice spanning a
    for (int j = 0; j <= 12; ++j) xs.insert(xs.end(), {i * s - a / 2, j * s - a / 2, 0.5e-3});
  for (int k = 1; k <= 15; ++k)  // the shank: a column up to z = 15.5 mm
    for (int i = -2; i <= 2; ++i)
      for (int j = -2; j <= 2; ++j) xs.insert(xs.end(), {i * s, j * s, 0.5e-3 + k * s});
  const Scene scene = bar_scene(3, false);
  const TaylorResult r = TaylorMeter(scene, TaylorOptions{}).measure(bar_frame(xs, 3));
  EXPECT_EQ(r.axis, 2);
  EXPECT_NEAR(r.L, 15.5e-3, 1e-15);
  EXPECT_NEAR(r.D, 4 * a / kPi, 1e-12);
  EXPECT_NEAR(r.D_min, a, 1e-12);
  EXPECT_NEAR(r.D_max, a * std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(r.D_radius, a * std::sqrt(2.0), 1e-12);
  TaylorOptions surf;
  surf.surface = true;
  const TaylorResult q = TaylorMeter(scene, surf).measure(bar_frame(xs, 3));
  EXPECT_NEAR(q.D, r.D + s, 1e-12);  // spacing = cell / particles per cell = 1 mm
  EXPECT_NEAR(q.L, r.L + s / 2, 1e-12);
}

// A round foot sampled densely: the mean caliper width is its diameter within the sampling
// (the inscribed polygon's perimeter falls short of the circle's by < 0.1% here).
TEST(TaylorMeter, RoundFootGivesItsDiameter) {
  const double R = 6.6e-3;
  std::vector<double> xs;
  for (int k = 0; k < 720; ++k)
    xs.insert(xs.end(), {R * std::cos(2 * kPi * k / 720), R * std::sin(2 * kPi * k / 720), 0.5e-3});
  for (int k = 1; k <= 20; ++k) xs.insert(xs.end(), {0, 0, 0.5e-3 + k * 1e-3});
  const TaylorResult r =
      TaylorMeter(bar_scene(3, false), TaylorOptions{}).measure(bar_frame(xs, 3));
  EXPECT_NEAR(r.D, 2 * R, 1e-3 * 2 * R);
  EXPECT_NEAR(r.D_max, 2 * R, 1e-12);
  EXPECT_NEAR(r.D_radius, 2 * R, 1e-12);
}

// In plane strain the foot is a strip: D is its width; in axisymmetry (x the radius, y the
// axis) twice the largest radius, whatever the axis option would pick.
TEST(TaylorMeter, PlaneStrainWidthAndAxisymmetricRadius) {
  std::vector<double> xs;
  for (int i = 0; i <= 10; ++i) xs.insert(xs.end(), {1e-3 + i * 1e-3, 0.5e-3});  // foot: x 1..11 mm
  for (int k = 1; k <= 20; ++k) xs.insert(xs.end(), {3e-3, 0.5e-3 + k * 1e-3});
  const TaylorResult p =
      TaylorMeter(bar_scene(2, false), TaylorOptions{}).measure(bar_frame(xs, 2));
  EXPECT_EQ(p.axis, 1);
  EXPECT_NEAR(p.D, 10e-3, 1e-15);
  const TaylorResult a = TaylorMeter(bar_scene(2, true), TaylorOptions{}).measure(bar_frame(xs, 2));
  EXPECT_EQ(a.axis, 1);
  EXPECT_NEAR(a.D, 22e-3, 1e-15);
  TaylorOptions radial;
  radial.axis = 0;
  EXPECT_THROW(TaylorMeter(bar_scene(2, true), radial).measure(bar_frame(xs, 2)), InputError);
}

}  // namespace
}  // namespace mpm
