// Rigid and deformable particles in the same cells: the constitutive update runs on blocks of
// consecutive particles of one material, and a rigid particle must end a block (before that
// fix a block spanned the rigid particle: it got stress, and the block's last deformable
// particle got none). A block compressed by a rigid pusher whose particles sit inside the
// block's cells, in both solvers: rigid particles keep zero stress, and every deformable
// particle of the strained cells next to them is stressed (the bug shifted the velocity
// gradients of a block by one particle and left its last particles without an update: 8 of
// the 96 here, in both solvers).
#include <gtest/gtest.h>

#include "fixtures.hpp"
#include "mpm/solver/explicit/explicit_solver.hpp"
#include "mpm/solver/implicit/implicit_solver.hpp"

namespace mpm {
namespace {

using testing::block;
using testing::elastic;
using testing::lattice;
using testing::scene_with;

template <class Solver>
void check(bool implicit) {
  const double h = 1e-3, rho = 7800, v = 1.0;
  Scene s = scene_with(elastic(200e9, 0.3, rho), 2, h, 1.0);
  BodySpec pusher;
  pusher.name = "pusher";
  pusher.rigid = true;
  pusher.velocity = Vec3(v, 0, 0);
  s.bodies.push_back(pusher);
  s.boundary.face[1] = BoundaryType::Fixed;
  if (implicit) s.solver.type = SolverType::Implicit;
  // Taller than wide: the slab axis (binning.hpp) is y, so a chunk holds whole rows of cells
  // along x, the shared cells and the strained ones in one constitutive pass.
  const Lattice lat = lattice(2, Vec3::Zero(), h, {8, 10, 1});
  ColumnStore cols = block<2>(lat, IVec<2>(4, 1), IVec<2>(8, 9), 2, rho,
                              [](const Vec<2>&) { return Vec<2>::Zero(); });
  // In the first cell column, the left particle of each row is rigid: rigid and deformable
  // particles share every cell there, and interleave in cell order.
  auto p = view<2>(cols);
  for (std::size_t i = 0; i < p.n; ++i)
    if (p.x[i][0] < 4.3e-3) {
      cols.get<std::uint8_t>(col::material)[i] = kRigidMaterial;
      cols.get<std::uint8_t>(col::body)[i] = 1;
      p.v[i] = Vec<2>(v, 0);
    }
  Solver solver(s, UniformGrid<2>(lat, s.boundary), cols);
  for (int k = 0; k < 5; ++k) solver.step(solver.stable_dt());
  p = view<2>(cols);
  int stressed = 0, deformable = 0;
  for (std::size_t i = 0; i < p.n; ++i) {
    if (p.material[i] == kRigidMaterial) {
      EXPECT_EQ(p.sigma[i].norm(), 0.0) << "rigid particle " << p.id[i];
      EXPECT_EQ(p.rho[i], rho) << "rigid particle " << p.id[i];  // untouched
    } else if (p.x[i][0] > 5e-3) {  // the cells beyond, all deformable and compressed
      ++deformable;
      stressed += p.sigma[i][0] < 0;  // compressed along x
    }
  }
  EXPECT_GT(deformable, 0);
  EXPECT_EQ(stressed, deformable);
}

TEST(RigidBlocks, RigidParticlesSharingCellsEndTheBlockExplicit) {
  check<UniformSolver<2>>(false);
}
TEST(RigidBlocks, RigidParticlesSharingCellsEndTheBlockImplicit) {
  check<ImplicitSolver<UniformGrid<2>>>(true);
}

}  // namespace
}  // namespace mpm
