// mpm-post debris on a cloud built by hand: the plane at the target's rear surface, the axis
// through the projectile's initial centre, the cloud (what lies behind the plane), the
// maximum and the percentiles of front and width.
#include <gtest/gtest.h>

#include <cstdint>

#include "mpm/particles.hpp"
#include "mpm/post.hpp"
#include "mpm/scene.hpp"
#include "mpm/stream.hpp"

namespace mpm {
namespace {

constexpr double kS = 1e-3;  // particle spacing: 2 mm cells, 2 particles per cell

Scene two_bodies() {
  Scene s;
  s.dimension = 3;
  s.grid.cell_size = 2e-3;
  BodySpec target, proj;
  target.name = "plate";
  proj.name = "sphere";
  proj.velocity = Vec3(6580, 0, 0);
  s.bodies = {target, proj};
  return s;
}

struct Cloud {
  std::vector<Vec3> x;
  std::vector<std::uint8_t> body;
  void add(const Vec3& p, int b) { x.push_back(p), body.push_back(std::uint8_t(b)); }
  Frame frame(double time) const {
    Frame f;
    f.time = time;
    f.columns.add({col::x, ScalarType::F64, 3, "m"});
    f.columns.add({col::v, ScalarType::F64, 3, "m/s"});
    f.columns.add({col::body, ScalarType::U8, 1, "-"});
    f.columns.resize(x.size());
    auto* xs = f.columns.get<Vec3>(col::x);
    auto* bs = f.columns.get<std::uint8_t>(col::body);
    for (std::size_t i = 0; i < x.size(); ++i) xs[i] = x[i], bs[i] = body[i];
    return f;
  }
};

TEST(Debris, PlaneAxisPercentilesAndMaximum) {
  const Scene scene = two_bodies();
  // t = 0: a plate x in [0, 5] mm (particle centres), the projectile centred on y = z = 1 mm.
  Cloud start;
  for (int i = 0; i <= 5; ++i)
    for (int j = -10; j <= 10; ++j) start.add(Vec3(i * kS, j * kS, 0), 0);
  for (int i = -3; i <= -1; ++i) start.add(Vec3(i * kS, 1e-3, 1e-3), 1);
  const DebrisMeter meter(scene, start.frame(0), DebrisOptions{});

  // Later: particle k = 1..1000 lies k mm behind the plate's rear face (x = 5.5 mm) and k / 2
  // mm from the impact axis; material still in front of the rear face is not in the cloud.
  Cloud later;
  for (int k = 1; k <= 1000; ++k)
    later.add(Vec3(5.5e-3 + k * 1e-3, 1e-3 + 0.5e-3 * k, 1e-3), k % 2);
  for (int k = 0; k < 50; ++k) later.add(Vec3(5.0e-3 - k * 1e-3, 1e-3, 1e-3 + k * 1e-3), 0);
  const DebrisResult r = meter.measure(later.frame(30e-6));

  EXPECT_EQ(r.axis, 0);
  EXPECT_EQ(r.direction, 1);
  EXPECT_NEAR(r.plane, 5.5e-3, 1e-15);  // rear centres at 5 mm plus half a spacing
  EXPECT_EQ(r.cloud, 1000u);
  EXPECT_EQ(r.total, 1050u);
  // Nearest rank of 1000 values 1..1000 mm: the p-th percentile is the ceil(10 p)-th value.
  const double tol = 1e-12;
  EXPECT_NEAR(r.front_max, 1.000, tol);
  EXPECT_NEAR(r.front_p99, 0.990, tol);
  EXPECT_NEAR(r.front_p995, 0.995, tol);
  EXPECT_NEAR(r.front_p999, 0.999, tol);
  EXPECT_NEAR(r.front, 0.995, tol);      // the headline: the 99.5th percentile by default
  EXPECT_NEAR(r.width_max, 1.000, tol);  // twice the distance from the axis
  EXPECT_NEAR(r.width_p995, 0.995, tol);
  EXPECT_NEAR(r.width, 0.995, tol);

  DebrisOptions p90;
  p90.percentile = 90;
  const DebrisResult q = DebrisMeter(scene, start.frame(0), p90).measure(later.frame(30e-6));
  EXPECT_NEAR(q.front, 0.900, tol);
  EXPECT_NEAR(q.width, 0.900, tol);
}

}  // namespace
}  // namespace mpm
