// The explicit solver on graded grids: particle splitting conserves mass, momentum and energy
// exactly (004, section 3.3) and places the children in the parent's extent (eq. 23); loads
// keep momentum = impulse through transition cells; a stress wave crossing level interfaces
// keeps the leapfrog energy balance; particles stay in cell order; the bulk viscosity takes
// each particle's own cell as its length.
#include <gtest/gtest.h>

#include <cstring>
#include <memory>

#include "fixtures.hpp"
#include "mpm/solver/explicit/graded_solver.hpp"

namespace mpm {
namespace {

using testing::block;
using testing::elastic;
using testing::lattice;
using testing::scene_with;

LevelSpec level_box(int level, const Vec3& lo, const Vec3& hi) {
  LevelSpec l;
  l.level = level;
  l.min = lo;
  l.max = hi;
  l.loc = {"test", 1, "grid.levels.0"};
  return l;
}

/// Sums over the particles in long double, so that their own rounding (1e-19 relative) does
/// not hide what the split does.
struct Sums {
  long double m = 0, kinetic = 0, internal = 0;
  long double momentum[3] = {0, 0, 0};
};

template <int D>
Sums sums(ColumnStore& cols) {
  const ParticleView<D> p = view<D>(cols);
  Sums s;
  for (std::size_t i = 0; i < p.n; ++i) {
    if (p.material[i] == kRigidMaterial) continue;
    s.m += p.m[i];
    s.kinetic += 0.5L * p.m[i] * p.v[i].squaredNorm();
    s.internal += (long double)p.m[i] * p.e[i];
    for (int a = 0; a < D; ++a) s.momentum[a] += (long double)p.m[i] * p.v[i][a];
  }
  return s;
}

/// Sets every particle's level to 1 (made at the level-1 spacing), so that those inside a
/// level-2 box split in the first step.
void all_coarse(ColumnStore& cols) {
  auto* level = cols.get<std::uint8_t>(col::level);
  std::fill(level, level + cols.size(), std::uint8_t(1));
}

// A block of coarse particles (2 x 2 per level-1 cell) moving at a uniform velocity, carrying
// specific internal energy, runs into a level-2 box. The total mass stays the same exactly
// (each child has m / 2^D, exact in binary; 1e-17 leaves the long-double sums' rounding).
// Every step, the sums the kernels computed before the split (solver.balance(), double sums
// in chunk order) equal the sums over the particles after it: momentum, kinetic and internal
// energy are conserved by the split to the rounding of those double sums of ~10^3 terms
// (N eps = 1e-13, 1e-12 with a margin).
template <int D>
void split_conserves() {
  const double h = 1e-3, rho = 2700;
  Scene s = scene_with(elastic(70e9, 0.3, rho), D, h, 1.0);
  s.grid.domain_given = true;
  s.grid.levels.push_back(level_box(2, Vec3(8e-3, 0, 0), Vec3(14e-3, 8e-3, 8e-3)));
  const Lattice lat = lattice(D, Vec3::Zero(), h, {16, 8, D == 3 ? 8 : 1});
  Vec<D> v0;
  for (int a = 0; a < D; ++a) v0[a] = a == 0 ? 400.0 : 30.0 * a;
  ColumnStore cols = block<D>(lat, IVec<D>::Constant(2), IVec<D>::Constant(5), 2, rho,
                              [&](const Vec<D>&) { return v0; });
  GradedSolver<D> solver(s, GradedGrid<D>(lat, s), cols);
  all_coarse(cols);
  {
    auto* e = cols.get<double>(col::e);
    for (std::size_t i = 0; i < cols.size(); ++i) e[i] = 1e3 * (1 + i % 3);
  }
  const std::size_t n0 = cols.size();
  const long double m0 = sums<D>(cols).m;
  long last_splits = 0;
  int split_steps = 0;
  while (solver.time() < 12e-6) {
    solver.step(solver.stable_dt());
    const Sums after = sums<D>(cols);
    const Balance& before = solver.balance();
    EXPECT_NEAR(double(after.m), double(m0), 1e-17 * double(m0));
    EXPECT_NEAR(double(after.kinetic), before.kinetic, 1e-12 * before.kinetic);
    EXPECT_NEAR(double(after.internal), before.internal, 1e-12 * before.internal);
    for (int a = 0; a < D; ++a)
      EXPECT_NEAR(double(after.momentum[a]), before.momentum[a], 1e-12 * before.momentum.norm());
    if (solver.splits() > last_splits) ++split_steps, last_splits = solver.splits();
  }
  EXPECT_GT(split_steps, 2);  // the block enters the box over several steps
  EXPECT_EQ(cols.size(), n0 + std::size_t(solver.splits()) * ((1 << D) - 1));
  // Every particle inside the box is of level 2 now.
  const ParticleView<D> p = view<D>(cols);
  const auto* level = cols.get<std::uint8_t>(col::level);
  long fine = 0;
  for (std::size_t i = 0; i < p.n; ++i)
    if (solver.grid().level_at(p.x[i]) == 2) {
      ASSERT_EQ(level[i], 2);
      ++fine;
    }
  EXPECT_GT(fine, 0);
}

TEST(GradedSplit, ConservesMassMomentumAndEnergyExactly3D) {
  split_conserves<3>();
}
TEST(GradedSplit, ConservesMassMomentumAndEnergyExactly2D) {
  split_conserves<2>();
}

// One coarse particle at rest inside a level-2 box splits into 2^D children at the centres of
// the 2^D parts of its extent (004, eq. 23: L = L0 (1 + eps), eps = 0 here), each with an
// eighth (a quarter) of its mass and its stress, energy and velocity; child 0 keeps its id.
template <int D>
void split_geometry() {
  const double h = 1e-3, rho = 8000;
  Scene s = scene_with(elastic(200e9, 0.3, rho), D, h, 1.0);
  s.bodies[0].particles_per_cell = 2;
  s.grid.domain_given = true;
  s.grid.levels.push_back(level_box(2, Vec3(2e-3, 2e-3, 2e-3), Vec3(6e-3, 6e-3, 6e-3)));
  const Lattice lat = lattice(D, Vec3::Zero(), h, {8, 8, D == 3 ? 8 : 1});
  ColumnStore cols = block<D>(lat, IVec<D>::Constant(3), IVec<D>::Constant(4), 1, rho,
                              [](const Vec<D>&) { return Vec<D>::Zero(); });
  cols.resize(1);  // one particle at the centre of cell (3, 3, 3)
  auto* m = cols.get<double>(col::m);
  m[0] = rho * std::pow(0.5e-3, D);  // made with the level-1 spacing h / 2
  GradedSolver<D> solver(s, GradedGrid<D>(lat, s), cols);
  auto* level = cols.get<std::uint8_t>(col::level);
  level[0] = 1;  // it comes from level 1
  auto* sigma = cols.get<Sym>(col::sigma);
  sigma[0] << 1e6, 2e6, -3e6, 4e6, 5e6, 6e6;  // deviatoric: the linear EOS keeps p = 0
  const Vec<D> x0 = view<D>(cols).x[0];
  const Sym s0 = sigma[0];
  solver.step(1e-12);
  const ParticleView<D> p = view<D>(cols);
  ASSERT_EQ(p.n, std::size_t(1 << D));
  EXPECT_EQ(solver.splits(), 1);
  Vec<D> centroid = Vec<D>::Zero();
  for (std::size_t i = 0; i < p.n; ++i) {
    EXPECT_DOUBLE_EQ(p.m[i], rho * std::pow(0.5e-3, D) / (1 << D));
    EXPECT_EQ(cols.get<std::uint8_t>(col::level)[i], 2);
    for (int a = 0; a < D; ++a) EXPECT_NEAR(std::abs(p.x[i][a] - x0[a]), 0.125e-3, 1e-12);
    centroid += p.x[i] / double(p.n);
    // The stress is copied (the step changed it by at most rounding: the particle is at rest).
    EXPECT_LT((p.sigma[i] - s0).norm(), 1e-6 * s0.norm());
  }
  EXPECT_LT((centroid - x0).norm(), 1e-15);
  EXPECT_EQ(p.id[0], 0u);
  for (std::size_t i = 1; i < p.n; ++i) EXPECT_EQ(p.id[i], std::uint32_t(i));
}

TEST(GradedSplit, ChildrenFillTheParentsExtent3D) {
  split_geometry<3>();
}
TEST(GradedSplit, ChildrenFillTheParentsExtent2D) {
  split_geometry<2>();
}

// A free elastic bar crossing a level-2 box, pulled at one end by a constant force F: its
// momentum grows by F t exactly (the load is the only external force; the transition shape
// functions sum to one, their gradients to zero), to 1e-9 of F t.
template <int D>
void load_impulse() {
  const double h = 1e-3;
  Scene s = scene_with(elastic(70e9, 0.3, 2700), D, h, 1.0);
  s.grid.domain_given = true;
  s.grid.levels.push_back(level_box(2, Vec3(4e-3, 0, 0), Vec3(8e-3, 8e-3, 8e-3)));
  LoadSpec load;
  load.body = 0;
  load.force = Vec3(250.0, -30.0, D == 3 ? 10.0 : 0.0);
  load.region_given = true;
  load.region_min = Vec3(8e-3, -1, -1);
  load.region_max = Vec3(9e-3, 1, 1);
  s.loads.push_back(load);
  const Lattice lat = lattice(D, Vec3::Zero(), h, {16, 8, D == 3 ? 8 : 1});
  IVec<D> hi = IVec<D>::Constant(4);
  hi[0] = 9;
  ColumnStore cols = block<D>(lat, IVec<D>::Constant(2), hi, 2, 2700,
                              [](const Vec<D>&) { return Vec<D>::Zero(); });
  GradedSolver<D> solver(s, GradedGrid<D>(lat, s), cols);
  all_coarse(cols);
  while (solver.time() < 2e-6) solver.step(std::min(solver.stable_dt(), 2e-6 - solver.time()));
  const Vec3 expect = load.force * solver.time();
  for (int a = 0; a < D; ++a)
    EXPECT_NEAR(solver.balance().momentum[a], expect[a], 1e-9 * load.force.norm() * solver.time());
  EXPECT_GT(solver.splits(), 0);  // the coarse particles in the box split in the first step
}

TEST(GradedLoads, ImpulseEqualsMomentumThroughTransitionCells3D) {
  load_impulse<3>();
}
TEST(GradedLoads, ImpulseEqualsMomentumThroughTransitionCells2D) {
  load_impulse<2>();
}

// A compression pulse crossing two level interfaces of a 2D bar: the energy central
// differences conserve (kinetic at the half steps plus internal) stays within 1% of the
// initial kinetic energy (MUSL dissipates a little; a coarse-fine interface that reflected or
// created energy would show here), and particles stay in cell order after every sort.
TEST(GradedSolver, PulseThroughLevelInterfacesKeepsEnergy) {
  const double h = 1e-3;
  Scene s = scene_with(elastic(70e9, 0.0, 2700), 2, h, 1.0);
  s.grid.domain_given = true;
  s.grid.levels.push_back(level_box(2, Vec3(20e-3, 0, 0), Vec3(40e-3, 4e-3, 0)));
  s.boundary.face[2] = s.boundary.face[3] = BoundaryType::Slip;
  const Lattice lat = lattice(2, Vec3::Zero(), h, {60, 4, 1});
  ColumnStore cols = block<2>(lat, IVec<2>(1, 0), IVec<2>(59, 4), 2, 2700, [](const Vec<2>& x) {
    const double r = (x[0] - 10e-3) / 3e-3;
    return Vec<2>(r * r < 1 ? 2.0 * (1 + std::cos(3.14159265358979 * r)) : 0.0, 0.0);
  });
  GradedSolver<2> solver(s, GradedGrid<2>(lat, s), cols);
  const double e0 = solver.balance().kinetic;
  const double c = std::sqrt(70e9 / 2700);
  while (solver.time() < 35e-3 / c) {
    solver.step(solver.stable_dt());
    EXPECT_NEAR(solver.balance().leapfrog_total, e0, 0.01 * e0);
  }
  // The pulse crossed the box: the material beyond x = 40 mm moves.
  const ParticleView<2> p = view<2>(cols);
  double beyond = 0;
  for (std::size_t i = 0; i < p.n; ++i)
    if (p.x[i][0] > 42e-3) beyond += 0.5 * p.m[i] * p.v[i].squaredNorm();
  EXPECT_GT(beyond, 0.1 * e0);  // the right-going half: a quarter of e0 as kinetic energy
  // Cell order: the bins of the last sort are in increasing key order.
  const auto& bins = solver.binning().bins();
  for (std::size_t b = 1; b < bins.size(); ++b) ASSERT_LT(bins[b - 1].key, bins[b].key);
}

// The artificial bulk viscosity's length is the particle's own cell: q = rho h^2 C0 tr(D)^2 in
// compression with the quadratic term alone, h the particle's level's cell (a shock spreads
// over the cells it crosses), while the time step stays the finest cell's. A block compressed
// uniformly, v = -rate (x - x_c), half of it in a level-2 box: one step with the viscosity and
// one without, from the same state with the same dt, differ in each particle's stress by -q
// on the diagonal (a linear EOS: the pressure does not depend on the energy the viscosity
// adds), and q matches the formula with the particle's tr(D) from its density change (000,
// eq. 14) and its cell's h, to 1e-9 (the round-off of tr(D) dt ~ 1e-5 from the densities).
// Measured with the finest cell everywhere, q in the coarse level would be 4x too small.
template <int D>
void viscosity_takes_the_cell() {
  const double h = 1e-3, rho0 = 2700, rate = 2e3;
  Scene s = scene_with(elastic(70e9, 0.3, rho0), D, h, 1.0);
  s.grid.domain_given = true;
  s.grid.levels.push_back(level_box(2, Vec3(6e-3, 0, 0), Vec3(12e-3, 8e-3, 8e-3)));
  const Lattice lat = lattice(D, Vec3::Zero(), h, {16, 8, D == 3 ? 8 : 1});
  const Vec<D> centre = Vec<D>::Constant(4e-3);
  const auto squeeze = [&](const Vec<D>& x) { return Vec<D>(-rate * (x - centre)); };
  IVec<D> lo = IVec<D>::Constant(1), hi = IVec<D>::Constant(7);
  hi[0] = 11;
  auto run = [&](double C0, double dt) {
    Scene sc = s;
    sc.solver.bulk_quadratic = C0;
    auto cols = std::make_unique<ColumnStore>(block<D>(lat, lo, hi, 2, rho0, squeeze));
    GradedSolver<D> solver(sc, GradedGrid<D>(lat, sc), *cols);
    if (dt > 0) solver.step(dt);
    return std::make_pair(std::move(cols), dt > 0 ? dt : solver.stable_dt());
  };
  const double C0 = 1.5;
  const double dt = 0.5 * run(C0, 0).second;  // well inside the step with viscosity
  const auto with = run(C0, dt).first;
  const auto without = run(0.0, dt).first;
  const ParticleView<D> a = view<D>(*with), b = view<D>(*without);
  const GradedGrid<D> grid(lat, s);
  ASSERT_EQ(a.n, b.n);
  std::vector<std::size_t> of_id(b.n);
  for (std::size_t j = 0; j < b.n; ++j) of_id[b.id[j]] = j;
  int coarse = 0, fine = 0;
  for (std::size_t i = 0; i < a.n; ++i) {
    const std::size_t j = of_id[a.id[i]];
    ASSERT_DOUBLE_EQ(a.rho[i], b.rho[j]);  // the same motion in the first step
    const double trD = (rho0 / a.rho[i] - 1.0) / dt;
    ASSERT_LT(trD, 0.0);
    // The cell the particle was binned in: the one it is in (it moved under a micrometre, a
    // quarter of a fine cell from the faces), at the new density (the update's).
    const int level = grid.level_at(a.x[i]);
    const double h_cell = grid.level_h(level);
    const double q = a.rho[i] * C0 * h_cell * h_cell * trD * trD;
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(b.sigma[j][c] - a.sigma[i][c], q, 1e-9 * q) << "particle " << a.id[i];
    ++(level == 1 ? coarse : fine);
  }
  EXPECT_GT(coarse, 0);
  EXPECT_GT(fine, 0);
}
TEST(GradedSolver, BulkViscosityTakesTheParticlesOwnCell3D) {
  viscosity_takes_the_cell<3>();
}
TEST(GradedSolver, BulkViscosityTakesTheParticlesOwnCell2D) {
  viscosity_takes_the_cell<2>();
}

}  // namespace
}  // namespace mpm

namespace mpm {
namespace {

/// Appends the particles of b to a (same columns).
void append(ColumnStore& a, const ColumnStore& b) {
  const std::size_t n = a.size();
  a.resize(n + b.size());
  for (const Column& c : b.columns()) {
    Column& d = a.at(c.info().name);
    std::memcpy(d.data() + n * c.info().element_bytes(), c.data(), c.bytes());
  }
}

// Adaptive placement: a level-2 box that follows a projectile (LevelSpec::follow). The box
// moves with the projectile's mass centre in whole level-1 cells, the grid is rebuilt, and the
// target's coarse particles the moving box reaches split. Nothing touches the projectile yet,
// so momentum stays exactly (to rounding, 1e-12) what it was, and mass too.
TEST(GradedFollow, BoxMovesWithTheProjectileAndSplitsWhatItReaches) {
  const double h = 1e-3, rho = 7800, v = 1000;
  Scene s = scene_with(elastic(200e9, 0.3, rho), 2, h, 1.0);
  BodySpec target = s.bodies[0];
  target.name = "target";
  s.bodies.push_back(target);
  s.grid.domain_given = true;
  LevelSpec box = level_box(2, Vec3(1e-3, 0, 0), Vec3(8e-3, 8e-3, 0));
  box.follow = 0;
  s.grid.levels.push_back(box);
  const Lattice lat = lattice(2, Vec3::Zero(), h, {40, 8, 1});
  ColumnStore cols = block<2>(lat, IVec<2>(2, 2), IVec<2>(5, 6), 2, rho,
                              [&](const Vec<2>&) { return Vec<2>(v, 0); });
  ColumnStore far = block<2>(lat, IVec<2>(13, 0), IVec<2>(30, 8), 2, rho,
                             [](const Vec<2>&) { return Vec<2>::Zero(); });
  std::fill(far.get<std::uint8_t>(col::body), far.get<std::uint8_t>(col::body) + far.size(), 1);
  append(cols, far);
  auto* id = cols.get<std::uint32_t>(col::id);
  for (std::size_t i = 0; i < cols.size(); ++i) id[i] = std::uint32_t(i);
  GradedSolver<2> solver(s, GradedGrid<2>(lat, s), cols);
  all_coarse(cols);
  const double p0 = solver.balance().momentum[0];
  const long rev0 = solver.grid().revision();
  while (solver.time() < 7e-6) solver.step(std::min(solver.stable_dt(), 7e-6 - solver.time()));
  EXPECT_NEAR(solver.grid().box_offset()[0], v * solver.time(), 0.5e-3 + 1e-9);  // nearest cell
  EXPECT_NEAR(solver.grid().box_offset()[1], 0.0, 1e-12);
  EXPECT_GE(solver.grid().revision() - rev0, 6);  // rebuilt at each whole cell
  EXPECT_GT(solver.splits(), 0);                  // target particles reached by the box
  EXPECT_NEAR(solver.balance().momentum[0], p0, 1e-12 * p0);
  // The split particles are the target's, inside the moved box.
  const ParticleView<2> p = view<2>(cols);
  const auto* level = cols.get<std::uint8_t>(col::level);
  for (std::size_t i = 0; i < p.n; ++i)
    if (p.body[i] == 1 && level[i] == 2) {
      ASSERT_GE(p.x[i][0], 13e-3);
      ASSERT_LE(p.x[i][0], 8e-3 + solver.grid().box_offset()[0]);
    }
}

}  // namespace
}  // namespace mpm
