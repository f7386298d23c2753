// mpm-post debris on a cloud built by hand: the plane at the target's rear surface, the axis
// through the projectile's initial centre, the cloud (what lies behind the plane), the
// maximum and the percentiles of front and width.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "mpm/core/error.hpp"
#include "mpm/post/post.hpp"
#include "mpm/scene/particles.hpp"
#include "mpm/scene/scene.hpp"
#include "mpm/stream/stream.hpp"

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
  int dim = 3;
  std::vector<Vec3> x;
  std::vector<std::uint8_t> body;
  std::vector<double> m;  ///< empty: frames without masses
  void add(const Vec3& p, int b) { x.push_back(p), body.push_back(std::uint8_t(b)); }
  Frame frame(double time) const {
    Frame f;
    f.time = time;
    f.columns.add({col::x, ScalarType::F64, dim, "m"});
    f.columns.add({col::v, ScalarType::F64, dim, "m/s"});
    f.columns.add({col::body, ScalarType::U8, 1, "-"});
    if (!m.empty()) f.columns.add({col::m, ScalarType::F64, 1, "kg"});
    f.columns.resize(x.size());
    auto* xs = reinterpret_cast<double*>(f.columns.at(col::x).data());
    auto* bs = f.columns.get<std::uint8_t>(col::body);
    for (std::size_t i = 0; i < x.size(); ++i) {
      for (int a = 0; a < dim; ++a) xs[i * dim + a] = x[i][a];
      bs[i] = body[i];
    }
    if (!m.empty()) std::copy(m.begin(), m.end(), f.columns.get<double>(col::m));
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

  // From the impact face (plate centres from x = 0, surface at -0.5 mm): the same cloud, its
  // distances 6 mm longer (the plate's thickness); the width does not change.
  DebrisOptions impact;
  impact.face = DebrisFace::Impact;
  const DebrisResult f = DebrisMeter(scene, start.frame(0), impact).measure(later.frame(30e-6));
  EXPECT_NEAR(f.face_plane, -0.5e-3, 1e-15);
  EXPECT_EQ(f.cloud, 1000u);
  EXPECT_NEAR(f.front_max, 1.006, tol);
  EXPECT_NEAR(f.front_p995, 1.001, tol);
  EXPECT_NEAR(f.front_p999, 1.005, tol);
  EXPECT_EQ(f.width_p995, r.width_p995);

  DebrisOptions p90;
  p90.percentile = 90;
  const DebrisResult q = DebrisMeter(scene, start.frame(0), p90).measure(later.frame(30e-6));
  EXPECT_NEAR(q.front, 0.900, tol);
  EXPECT_NEAR(q.width, 0.900, tol);

  // Equal masses: the percentiles are by number, to the bit.
  later.m.assign(later.x.size(), 0.37);
  const DebrisResult e = meter.measure(later.frame(30e-6));
  EXPECT_FALSE(e.by_mass);
  EXPECT_EQ(e.front_p995, r.front_p995);
  EXPECT_EQ(e.width_p99, r.width_p99);
  // Heavier particles weigh more: k <= 500 weigh 1, the farther ones 3 (total 2000). The 99.5th
  // percentile is the smallest k whose cumulative mass 500 + 3 (k - 500) reaches 1990: k = 997
  // (by number: 995).
  for (int k = 1; k <= 1000; ++k) later.m[k - 1] = k <= 500 ? 1.0 : 3.0;
  const DebrisResult w = meter.measure(later.frame(30e-6));
  EXPECT_TRUE(w.by_mass);
  EXPECT_NEAR(w.front_p995, 0.997, tol);
  EXPECT_NEAR(w.front_max, 1.000, tol);
}

// An axisymmetric cloud (x the radius, y the axis): the axis is r = 0 whatever the projectile's
// particles (rings at r > 0) average to, the width is twice the radius, and a ring weighs its
// mass per radian, proportional to r. Rings k = 1..N at r_k = (k - 1/2) dr have cumulative
// masses proportional to k^2 / 2: the p-th percentile is ring ceil(N sqrt(p)), where counting
// particles would give ring ceil(N p).
TEST(Debris, AxisymmetricCloudWeighsRingsByTheirMass) {
  Scene scene = two_bodies();
  scene.dimension = 2;
  scene.axisymmetric = true;
  scene.bodies[1].velocity = Vec3(0, 6580, 0);
  Cloud start;
  start.dim = 2;
  for (int i = 0; i <= 5; ++i)
    for (int j = 0; j < 20; ++j) start.add(Vec3((j + 0.5) * kS, i * kS, 0), 0);  // plate y 0..5 mm
  for (int j = 0; j < 4; ++j) start.add(Vec3((j + 0.5) * kS, -2e-3, 0), 1);
  start.m.assign(start.x.size(), 1.0);
  const DebrisMeter meter(scene, start.frame(0), DebrisOptions{});

  const int N = 1000;
  const double dr = 0.1e-3;
  Cloud later;
  later.dim = 2;
  for (int k = 1; k <= N; ++k) {  // ring k: k mm behind the rear face (y = 5.5 mm)
    const double r = (k - 0.5) * dr;
    later.add(Vec3(r, 5.5e-3 + k * 1e-3, 0), 1);
    later.m.push_back(11350 * 1e-8 * r);  // rho A r
  }
  const DebrisResult a = meter.measure(later.frame(30e-6));
  EXPECT_EQ(a.axis, 1);
  EXPECT_NEAR(a.plane, 5.5e-3, 1e-15);
  EXPECT_NEAR(a.axis_point.x(), 0.0, 0.0);
  EXPECT_TRUE(a.by_mass);
  const double tol = 1e-12;
  auto ring = [&](double p) { return int(std::ceil(N * std::sqrt(p) - 1e-9)); };
  EXPECT_EQ(ring(0.995), 998);
  EXPECT_NEAR(a.front_p995, ring(0.995) * 1e-3, tol);
  EXPECT_NEAR(a.front_p99, ring(0.99) * 1e-3, tol);
  EXPECT_NEAR(a.front_p999, ring(0.999) * 1e-3, tol);
  EXPECT_NEAR(a.width_p995, 2 * (ring(0.995) - 0.5) * dr, tol);
  EXPECT_NEAR(a.width_max, 2 * (N - 0.5) * dr, tol);
  EXPECT_NEAR(a.front_max, N * 1e-3, tol);

  // The impact axis of an axisymmetric scene is y.
  DebrisOptions along_x;
  along_x.axis = 0;
  EXPECT_THROW(DebrisMeter(scene, start.frame(0), along_x), InputError);
  // Rings without masses cannot be weighed.
  later.m.clear();
  EXPECT_THROW(meter.measure(later.frame(30e-6)), InputError);
}

// Friends of friends: points closer than the linking length are one fragment, transitively,
// across the bins of the search; points farther apart are not.
TEST(Debris, FragmentsLinkTransitivelyAcrossBins) {
  const double link = 1e-3;
  std::vector<Vec3> chain, gaps;
  for (int k = 0; k < 40; ++k) {
    chain.push_back(Vec3(0.9e-3 * k, 0.3e-3 * (k % 2), -0.2e-3 * (k % 2)));  // steps 0.97 mm
    gaps.push_back(Vec3(1.01e-3 * k, 0, 0));                                 // steps 1.01 mm
  }
  for (const std::size_t s : fragment_sizes(chain, link)) EXPECT_EQ(s, 40u);
  for (const std::size_t s : fragment_sizes(gaps, link)) EXPECT_EQ(s, 1u);
  // Two blocks of 3 x 3 x 3 points 0.5 mm apart, 0.9 mm and 1.1 mm between their faces.
  std::vector<Vec3> blocks;
  for (const double x0 : {0.0, 1.9e-3, 5.1e-3})
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k) blocks.push_back(Vec3(x0 + 0.5e-3 * i, 0.5e-3 * j, 0.5e-3 * k));
  const std::vector<std::size_t> s = fragment_sizes(blocks, link);
  for (std::size_t i = 0; i < 54; ++i) EXPECT_EQ(s[i], 54u);   // 1.9 - 1.0 = 0.9 mm: linked
  for (std::size_t i = 54; i < 81; ++i) EXPECT_EQ(s[i], 27u);  // 5.1 - 2.9 = 2.2 mm: apart
}

// Only particles of fragments of at least --min-fragment particles count: isolated particles
// ahead of the cloud no longer set its front and width.
TEST(Debris, MinFragmentDropsIsolatedParticles) {
  const Scene scene = two_bodies();  // 2 mm cells: the default linking length
  Cloud start;
  for (int i = 0; i <= 5; ++i)
    for (int j = -10; j <= 10; ++j) start.add(Vec3(i * kS, j * kS, 0), 0);
  for (int i = -3; i <= -1; ++i) start.add(Vec3(i * kS, 1e-3, 1e-3), 1);
  // Behind the rear face (5.5 mm): a 5 x 5 x 5 block of particles 1 mm apart, its front face
  // 50 mm behind the plane and 4 mm off the axis at most; a pair 1.5 mm apart 60 mm behind;
  // three particles alone, 100, 120 and 140 mm behind, the last 80 mm off the axis.
  Cloud later;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
      for (int k = 0; k < 5; ++k)
        later.add(Vec3(5.5e-3 + 46e-3 + i * 1e-3, 1e-3 + (j - 2) * 1e-3, 1e-3 + (k - 2) * 1e-3), 1);
  later.add(Vec3(5.5e-3 + 58.5e-3, 1e-3, 1e-3), 0);
  later.add(Vec3(5.5e-3 + 60e-3, 1e-3, 1e-3), 0);
  later.add(Vec3(5.5e-3 + 100e-3, 1e-3, 1e-3), 0);
  later.add(Vec3(5.5e-3 + 120e-3, 1e-3, 1e-3), 0);
  later.add(Vec3(5.5e-3 + 140e-3, 1e-3 + 40e-3, 1e-3), 0);

  DebrisOptions all;
  const DebrisResult a = DebrisMeter(scene, start.frame(0), all).measure(later.frame(30e-6));
  EXPECT_NEAR(a.link, 2e-3, 1e-15);
  EXPECT_EQ(a.cloud, 130u);
  EXPECT_EQ(a.counted, 130u);
  EXPECT_EQ(a.fragments, 5u);
  EXPECT_EQ(a.singles, 3u);
  EXPECT_EQ(a.largest, 125u);
  EXPECT_NEAR(a.front_max, 0.140, 1e-12);
  EXPECT_NEAR(a.width_max, 0.080, 1e-12);

  DebrisOptions pairs;
  pairs.min_fragment = 2;
  const DebrisResult b = DebrisMeter(scene, start.frame(0), pairs).measure(later.frame(30e-6));
  EXPECT_EQ(b.counted, 127u);
  EXPECT_NEAR(b.front_max, 0.060, 1e-12);
  EXPECT_NEAR(b.width_max, 2 * std::sqrt(8e-6), 1e-12);  // the block's corners, (2, 2) mm off
  DebrisOptions blocks = pairs;
  blocks.min_fragment = 3;
  const DebrisResult c = DebrisMeter(scene, start.frame(0), blocks).measure(later.frame(30e-6));
  EXPECT_EQ(c.counted, 125u);
  EXPECT_NEAR(c.front_max, 0.050, 1e-12);
  // A linking length of 1.4 mm breaks the pair (1.5 mm apart) but keeps the block (1 mm).
  blocks.min_fragment = 2;
  blocks.link = 1.4e-3;
  const DebrisResult d = DebrisMeter(scene, start.frame(0), blocks).measure(later.frame(30e-6));
  EXPECT_EQ(d.fragments, 6u);
  EXPECT_EQ(d.counted, 125u);
}

// A quarter model (slip faces y = 0 and z = 0 through the plate and the projectile) measures
// as the whole cloud: the cloud of the whole model, mirrored by hand, and its quarter y, z > 0
// give the same front, width and fragments, to round-off (the axis point is a sum in another
// order). A fragment that lies across a plane is one fragment of the whole.
TEST(Debris, QuarterModelMeasuresAsTheWholeCloud) {
  Scene whole = two_bodies();
  whole.bodies[0].size = Vec3(6e-3, 40e-3, 40e-3);
  whole.bodies[0].translate = Vec3(2.5e-3, 0, 0);
  whole.bodies[1].shape = ShapeKind::Sphere;
  whole.bodies[1].radius = 2e-3;
  whole.bodies[1].translate = Vec3(-3e-3, 0, 0);
  Scene quarter = whole;
  quarter.grid.domain_given = true;
  quarter.grid.domain_min = Vec3(-10e-3, 0, 0);
  quarter.grid.domain_max = Vec3(200e-3, 30e-3, 30e-3);
  quarter.boundary.face[2] = quarter.boundary.face[4] = BoundaryType::Slip;  // y_min, z_min
  const Symmetry sym = scene_symmetry(quarter);
  ASSERT_EQ(sym.planes.size(), 2u);
  EXPECT_EQ(sym.planes[0].axis, 1);
  EXPECT_EQ(sym.planes[1].axis, 2);
  // The quarter's particles (centres off the planes), and the whole made of their images.
  Cloud start_q, later_q, start_w, later_w;
  for (int i = 0; i <= 5; ++i)
    for (int j = 0; j < 10; ++j)
      for (int k = 0; k < 10; ++k) start_q.add(Vec3(i * kS, (j + 0.5) * kS, (k + 0.5) * kS), 0);
  for (int i = -4; i <= -2; ++i) start_q.add(Vec3(i * kS, 0.5 * kS, 0.5 * kS), 1);
  // Later: a block astride the corner of the planes, particles along y = 0.5 mm (one fragment
  // across the plane y = 0 in the whole), and spread particles.
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k)
        later_q.add(Vec3(20e-3 + i * kS, (j + 0.5) * kS, (k + 0.5) * kS), 1);
  for (int i = 0; i < 30; ++i) later_q.add(Vec3(30e-3 + i * kS, 0.5 * kS, 10e-3), 0);
  for (int k = 1; k <= 200; ++k)
    later_q.add(Vec3(6e-3 + 0.7e-3 * k, 0.13e-3 * k + 0.2e-3, 0.11e-3 * (k % 37) + 0.1e-3), 0);
  for (const auto* part : {&start_q, &later_q}) {
    Cloud& w = part == &start_q ? start_w : later_w;
    for (std::size_t i = 0; i < part->x.size(); ++i)
      for (int im = 0; im < 4; ++im) w.add(sym.point_image(part->x[i], im), part->body[i]);
  }
  const DebrisResult a = DebrisMeter(whole, start_w.frame(0), {}).measure(later_w.frame(30e-6));
  const DebrisResult b = DebrisMeter(quarter, start_q.frame(0), {}).measure(later_q.frame(30e-6));
  EXPECT_TRUE(a.symmetry.planes.empty());
  EXPECT_EQ(b.symmetry.images(), 4);
  EXPECT_NEAR(b.plane, a.plane, 1e-15);
  EXPECT_EQ(b.cloud, a.cloud);
  EXPECT_EQ(b.total * 4, a.total);
  EXPECT_EQ(b.fragments, a.fragments);
  EXPECT_EQ(b.largest, a.largest);
  EXPECT_GE(a.largest, 36u * 4);  // the block's four images touch: one fragment of the whole
  const double tol = 1e-12;
  EXPECT_NEAR(b.front, a.front, tol);
  EXPECT_NEAR(b.front_max, a.front_max, tol);
  EXPECT_NEAR(b.width, a.width, tol);
  EXPECT_NEAR(b.width_max, a.width_max, tol);
  EXPECT_NEAR(b.width_p99, a.width_p99, tol);
  // Measured as it is (no planes), the quarter's cloud is narrower about the wrong axis.
  DebrisOptions cut;
  cut.symmetry = Symmetry{};
  const DebrisResult c = DebrisMeter(quarter, start_q.frame(0), cut).measure(later_q.frame(30e-6));
  EXPECT_EQ(c.cloud * 4, a.cloud);
  EXPECT_GT(std::abs(c.width_max - a.width_max), 1e-3);
}

}  // namespace
}  // namespace mpm
