// mpm-post crater on craters carved by hand: a quarter plate lattice from which a spherical cap
// (the crater) or a cylinder (a hole) is removed, and a sphere lying in the crater. The measures
// must give the carved depth and diameter within one particle spacing (the lattice samples the
// carved surface at that spacing: the nearest centre lies within a spacing of it), and the
// quarter model (mirror planes found in the scene) the same as the whole model mirrored by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <functional>

#include "mpm/post/crater.hpp"
#include "mpm/scene/particles.hpp"

namespace mpm {
namespace {

constexpr double kS = 0.5e-3;  // particle spacing: 1 mm cells, 2 particles per cell

/// A quarter scene: plate 20 x 20 x 10 mm whole, struck face z = 0; a ball of radius 2 mm above
/// it moving along -z; slip faces x_min and y_min through both.
Scene quarter_scene() {
  Scene s;
  s.dimension = 3;
  s.grid.cell_size = 1e-3;
  s.grid.domain_given = true;
  s.grid.domain_min = Vec3(0, 0, -12e-3);
  s.grid.domain_max = Vec3(12e-3, 12e-3, 6e-3);
  s.boundary.face[0] = s.boundary.face[2] = BoundaryType::Slip;
  BodySpec plate, ball;
  plate.name = "plate";
  plate.size = Vec3(20e-3, 20e-3, 10e-3);
  plate.translate = Vec3(0, 0, -5e-3);
  ball.name = "ball";
  ball.shape = ShapeKind::Sphere;
  ball.radius = 2e-3;
  ball.translate = Vec3(0, 0, 2.5e-3);
  ball.velocity = Vec3(0, 0, -800);
  s.bodies = {plate, ball};
  return s;
}

struct Points {
  std::vector<Vec3> x;
  std::vector<std::uint8_t> body;
  Frame frame(double time) const {
    Frame f;
    f.time = time;
    f.columns.add({col::x, ScalarType::F64, 3, "m"});
    f.columns.add({col::body, ScalarType::U8, 1, "-"});
    f.columns.resize(x.size());
    auto* xs = f.columns.get<Vec3>(col::x);
    auto* bs = f.columns.get<std::uint8_t>(col::body);
    for (std::size_t i = 0; i < x.size(); ++i) xs[i] = x[i], bs[i] = body[i];
    return f;
  }
  /// The lattice points of the quarter (centres at (i + 1/2) s) inside `inside`, as body b.
  void lattice(const Vec3& lo, const Vec3& hi, int b, const std::function<bool(const Vec3&)>& in) {
    for (double x = lo.x() + kS / 2; x < hi.x(); x += kS)
      for (double y = lo.y() + kS / 2; y < hi.y(); y += kS)
        for (double z = lo.z() + kS / 2; z < hi.z(); z += kS)
          if (in(Vec3(x, y, z))) this->x.push_back(Vec3(x, y, z)), body.push_back(std::uint8_t(b));
  }
  /// The whole: every point and its images in x = 0 and y = 0.
  Points whole() const {
    Points w;
    for (std::size_t i = 0; i < x.size(); ++i)
      for (const Vec3& m : {Vec3(1, 1, 1), Vec3(-1, 1, 1), Vec3(1, -1, 1), Vec3(-1, -1, 1)})
        w.x.push_back(x[i].cwiseProduct(m)), w.body.push_back(body[i]);
    return w;
  }
};

/// The plate lattice less `removed`, and the ball at `ball_centre`.
Points model(const std::function<bool(const Vec3&)>& removed, const Vec3& ball_centre) {
  Points p;
  p.lattice(Vec3(0, 0, -10e-3), Vec3(10e-3, 10e-3, 0), 0,
            [&](const Vec3& x) { return !removed(x); });
  p.lattice(Vec3(0, 0, ball_centre.z() - 2e-3), Vec3(2e-3, 2e-3, ball_centre.z() + 2e-3), 1,
            [&](const Vec3& x) { return (x - ball_centre).norm() < 2e-3; });
  return p;
}

TEST(Crater, SphericalCapCraterGivesItsDepthAndDiameter) {
  const Scene quarter = quarter_scene();
  const Points start = model([](const Vec3&) { return false; }, Vec3(0, 0, 2.5e-3));
  // The crater: a spherical cap 3.3 mm deep and 8.2 mm across at z = 0 (off the lattice), the
  // ball at its bottom.
  const double d = 3.3e-3, D = 8.2e-3, R = (D * D / 4 + d * d) / (2 * d);
  const Vec3 c(0, 0, R - d);
  const Points later =
      model([&](const Vec3& x) { return (x - c).norm() < R; }, Vec3(0, 0, 2e-3 - d));
  const CraterResult q = CraterMeter(quarter, start.frame(0), {}).measure(later.frame(30e-6));
  EXPECT_EQ(q.symmetry.images(), 4);
  EXPECT_EQ(q.axis, 2);
  EXPECT_EQ(q.direction, -1);
  EXPECT_NEAR(q.axis_point.x(), 0, 1e-15);
  EXPECT_NEAR(q.surface, 0, 1e-15);
  EXPECT_NEAR(q.thickness, 10e-3, 1e-12);
  EXPECT_FALSE(q.perforated);
  EXPECT_NEAR(q.depth, d, kS);
  EXPECT_NEAR(q.diameter, D, kS);
  ASSERT_EQ(q.penetration.size(), 1u);
  EXPECT_EQ(q.penetration[0].body, "ball");
  EXPECT_NEAR(q.penetration[0].depth, d, kS);  // the ball's nose at the crater's bottom
  // Measured as it is, the quarter's crater is off its axis: the model's corner is not the
  // crater's centre, so the "crater" seen from the corner is the quarter's, half as wide.
  CraterOptions cut;
  cut.symmetry = Symmetry{};
  const CraterResult c0 = CraterMeter(quarter, start.frame(0), cut).measure(later.frame(30e-6));
  EXPECT_GT(std::abs(c0.diameter - D), 2 * kS);
  // The whole model, mirrored by hand, without planes: the same crater.
  Scene whole = quarter;
  whole.boundary.face[0] = whole.boundary.face[2] = BoundaryType::Free;
  const CraterResult w =
      CraterMeter(whole, start.whole().frame(0), {}).measure(later.whole().frame(30e-6));
  EXPECT_TRUE(w.symmetry.planes.empty());
  EXPECT_NEAR(w.depth, q.depth, 1e-12);
  EXPECT_NEAR(w.diameter, q.diameter, 1e-12);
  EXPECT_NEAR(w.penetration[0].depth, q.penetration[0].depth, 1e-12);
}

TEST(Crater, HoleThroughThePlateIsPerforatedWithItsDiameter) {
  const Scene quarter = quarter_scene();
  const Points start = model([](const Vec3&) { return false; }, Vec3(0, 0, 2.5e-3));
  // A hole 5.2 mm across through the plate, its rim bulged; the ball 4 mm behind the plate.
  const double Dh = 5.2e-3;
  const Points later =
      model([&](const Vec3& x) { return std::hypot(x.x(), x.y()) < Dh / 2; }, Vec3(0, 0, -16e-3));
  const CraterResult q = CraterMeter(quarter, start.frame(0), {}).measure(later.frame(40e-6));
  EXPECT_TRUE(q.perforated);
  EXPECT_NEAR(q.diameter, Dh, kS);
  EXPECT_NEAR(q.depth, 10e-3, 1e-12);  // the whole thickness
  EXPECT_NEAR(q.penetration[0].depth, 18e-3, 1e-12 + kS);
  EXPECT_GT(q.penetration[0].depth, q.thickness);
}

}  // namespace
}  // namespace mpm
