// Loads and rigid bodies against momentum balances.
#include <gtest/gtest.h>

#include "fixtures.hpp"
#include "mpm/solver/explicit/explicit_solver.hpp"

namespace mpm {
namespace {

using testing::block;
using testing::elastic;
using testing::lattice;
using testing::scene_with;

// A free elastic bar pulled at one end by a constant force F: whatever the waves do, its
// momentum grows by F t exactly (the load is the only external force), in 3D and 2D.
template <int D>
void load_impulse() {
  const double h = 1e-3;
  Scene s = scene_with(elastic(70e9, 0.3, 2700), D, h, 1.0);
  LoadSpec load;
  load.body = 0;
  load.force = Vec3(250.0, -30.0, D == 3 ? 10.0 : 0.0);
  load.region_given = true;
  load.region_min = Vec3(8e-3, -1, -1);  // the last cell of the bar
  load.region_max = Vec3(9e-3, 1, 1);
  s.loads.push_back(load);
  const Lattice lat = lattice(D, Vec3::Zero(), h, {16, 8, D == 3 ? 8 : 1});
  ColumnStore cols = block<D>(
      lat, IVec<D>::Constant(2),
      IVec<D>::Constant(2) +
          [] {
            IVec<D> n = IVec<D>::Constant(2);
            n[0] = 7;
            return n;
          }(),
      2, 2700, [](const Vec<D>&) { return Vec<D>::Zero(); });
  UniformSolver<D> solver(s, UniformGrid<D>(lat, s.boundary), cols);
  while (solver.time() < 2e-6) solver.step(std::min(solver.stable_dt(), 2e-6 - solver.time()));
  const Vec3 expect = load.force * solver.time();
  for (int a = 0; a < D; ++a)
    EXPECT_NEAR(solver.balance().momentum[a], expect[a], 1e-9 * load.force.norm() * solver.time());
  EXPECT_GT(solver.balance().external_work, 0.0);
  // Only the particles in the region carry the force.
  auto p = view<D>(cols);
  int loaded = 0;
  for (std::size_t i = 0; i < p.n; ++i) loaded += p.f_ext[i].norm() > 0;
  EXPECT_EQ(loaded, D == 3 ? 2 * 16 : 2 * 4);  // two particle layers of the 2 x 2-cell section
}

TEST(Loads, ImpulseEqualsMomentum3D) {
  load_impulse<3>();
}
TEST(Loads, ImpulseEqualsMomentum2D) {
  load_impulse<2>();
}

// A rigid block pushes an elastic block at constant speed (no-slip on the nodes it touches).
// The rigid body keeps its velocity; the material's momentum changes by minus the impulse of
// the force it exerts on the rigid body, step by step.
TEST(Rigid, PushedBlockMomentumBalancesTheRigidForce) {
  const double h = 1e-3, rho = 7800;
  Scene s = scene_with(elastic(200e9, 0.3, rho), 3, h, 1.0);
  BodySpec pusher;
  pusher.name = "pusher";
  pusher.rigid = true;
  pusher.velocity = Vec3(5.0, 0, 0);
  s.bodies.push_back(pusher);
  const Lattice lat = lattice(3, Vec3::Zero(), h, {20, 6, 6});
  ColumnStore cols = block<3>(lat, IVec<3>(2, 1, 1), IVec<3>(10, 5, 5), 2, rho,
                              [](const Vec3& x) { return Vec3::Zero(); });
  // The first cell column of the block becomes the rigid pusher.
  {
    auto p = view<3>(cols);
    auto* mat = cols.get<std::uint8_t>(col::material);
    auto* body = cols.get<std::uint8_t>(col::body);
    for (std::size_t i = 0; i < p.n; ++i)
      if (p.x[i][0] < 3e-3) {
        mat[i] = kRigidMaterial;
        body[i] = 1;
        p.v[i] = pusher.velocity;
      }
  }
  UniformSolver<3> solver(s, UniformGrid<3>(lat, s.boundary), cols);
  Vec3 impulse = Vec3::Zero(), p0 = solver.balance().momentum;
  double last_dt = 0;
  while (solver.time() < 5e-6) {
    last_dt = std::min(solver.stable_dt(), 5e-6 - solver.time());
    solver.step(last_dt);
    impulse += solver.rigid_force()[1] * last_dt;
  }
  const Vec3 dp = solver.balance().momentum - p0;
  EXPECT_GT(dp.x(), 0.0);  // pushed along +x
  EXPECT_LT((dp + impulse).norm(), 1e-6 * dp.norm())
      << dp.transpose() << " vs " << impulse.transpose();
  // Rigid particles kept their velocity and moved with it.
  auto p = view<3>(cols);
  for (std::size_t i = 0; i < p.n; ++i) {
    if (p.material[i] == kRigidMaterial) {
      ASSERT_EQ(p.v[i], pusher.velocity);
    }
  }
  EXPECT_EQ(solver.rigid_force()[0].norm(), 0.0);  // body 0 is not rigid
}

}  // namespace
}  // namespace mpm
