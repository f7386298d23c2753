// The scatter strategies give the same Taylor bar to round-off; the default (colored) gives the
// same bits at any thread count, and every strategy the same bits when run twice.
#include <gtest/gtest.h>
#include <omp.h>

#include <filesystem>

#include "mpm/grid/lattice.hpp"
#include "mpm/prep/graded_voxelise.hpp"
#include "mpm/prep/voxelise.hpp"
#include "mpm/solver/explicit/explicit_solver.hpp"
#include "mpm/solver/explicit/graded_solver.hpp"
#include "mpm/solver/explicit/sparse_solver.hpp"

namespace mpm {
namespace {

/// The Taylor bar example at 0.76 mm cells, 12 us (about 170 steps: impact, plastic flow, the
/// particles re-sorted many times), with a strategy and a thread count; columns by particle id.
/// `graded`: the graded example (graded.toml) at 0.76 / 0.38 mm, whose coarse particles split
/// as they flow into the fine box by the wall. `sparse`: the scene on the sparse grid; `sorts`
/// receives the number of re-sorts.
ColumnStore taylor(ScatterStrategy strategy, int threads, bool graded = false, bool sparse = false,
                   long* sorts = nullptr) {
  const std::string path =
      std::string(MPM_EXAMPLES) + (graded ? "/taylor-bar/graded.toml" : "/taylor-bar/scene.toml");
  std::vector<std::string> sets{"solver.end_time=\"12 us\""};
  if (graded) sets.push_back("grid.cell_size=\"0.76 mm\"");
  const Scene scene = load_scene(path, sets);
  const Lattice lat = make_lattice(scene);
  std::vector<BodyReport> report;
  ColumnStore cols =
      graded ? std::move(prepare_graded(scene, lat, report).columns) : voxelise(scene, lat, report);
  const int saved = omp_get_max_threads();
  omp_set_num_threads(threads);
  auto run = [&](auto& solver) {
    while (solver.time() < scene.solver.end_time * (1 - 1e-12))
      solver.step(std::min(solver.stable_dt(), scene.solver.end_time - solver.time()));
  };
  if (graded) {
    GradedSolver<3> solver(scene, GradedGrid<3>(lat, scene), cols, strategy);
    run(solver);
    EXPECT_GT(solver.splits(), 0) << "the test should exercise splitting";
  } else if (sparse) {
    SparseSolver<3> solver(scene, SparseGrid<3>(lat, scene.boundary), cols, strategy);
    run(solver);
    if (sorts) *sorts = solver.binning().sorts();
  } else {
    UniformSolver<3> solver(scene, UniformGrid<3>(lat, scene.boundary), cols, strategy);
    run(solver);
    if (sorts) *sorts = solver.binning().sorts();
  }
  omp_set_num_threads(saved);
  // Back into id order.
  const auto* id = cols.get<std::uint32_t>(col::id);
  std::vector<std::uint32_t> perm(cols.size());
  for (std::size_t i = 0; i < cols.size(); ++i) perm[id[i]] = std::uint32_t(i);
  cols.gather(perm);
  return cols;
}

bool bitwise_equal(const ColumnStore& a, const ColumnStore& b) {
  if (a.size() != b.size() || a.columns().size() != b.columns().size()) return false;
  for (const auto& c : a.columns()) {
    const Column* d = b.find(c.info().name);
    if (!d || d->bytes() != c.bytes() || std::memcmp(c.data(), d->data(), c.bytes()) != 0)
      return false;
  }
  return true;
}

TEST(Strategies, DefaultIsBitwiseIdenticalAtOneAndTwoThreads) {
  const ColumnStore one = taylor(ScatterStrategy::Colored, 1);
  const ColumnStore two = taylor(ScatterStrategy::Colored, 2);
  EXPECT_TRUE(bitwise_equal(one, two));
}

// Summation order is all that differs between strategies: positions agree to round-off
// amplified by ~170 steps of plastic flow. Measured differences are ~1e-16 m relative to the
// bar's size (1e-12 relative in stress); the bound leaves four orders of margin and is still
// far below any physical difference (a 0.1% change in D is 1e-5 m).
TEST(Strategies, AllAgreeToRoundOffOnTheTaylorBar) {
  const ColumnStore ref = taylor(ScatterStrategy::Colored, 2);
  const auto* x0 = reinterpret_cast<const Vec3*>(ref.at(col::x).data());
  const auto* s0 = reinterpret_cast<const Sym*>(ref.at(col::sigma).data());
  for (ScatterStrategy st :
       {ScatterStrategy::LRSlabs, ScatterStrategy::ArrayExpansion, ScatterStrategy::Patch}) {
    const ColumnStore other = taylor(st, 2);
    ASSERT_EQ(other.size(), ref.size());
    const auto* x1 = reinterpret_cast<const Vec3*>(other.at(col::x).data());
    const auto* s1 = reinterpret_cast<const Sym*>(other.at(col::sigma).data());
    double dx = 0, ds = 0, smax = 0;
    for (std::size_t i = 0; i < ref.size(); ++i) {
      dx = std::max(dx, (x1[i] - x0[i]).norm());
      ds = std::max(ds, (s1[i] - s0[i]).norm());
      smax = std::max(smax, s0[i].norm());
    }
    EXPECT_LT(dx, 1e-12) << to_string(st) << ": m";
    EXPECT_LT(ds, 1e-8 * smax) << to_string(st);
    // A fixed strategy and thread count gives the same bits twice.
    EXPECT_TRUE(bitwise_equal(other, taylor(st, 2))) << to_string(st);
  }
}

// The graded grid (transition cells, hanging nodes, splitting) under the strategies that work
// on any grid: the same bits at 1 and 2 threads by default, round-off between strategies.
TEST(Strategies, GradedGridDeterministicAndStrategiesAgree) {
  const ColumnStore ref = taylor(ScatterStrategy::Colored, 2, true);
  EXPECT_TRUE(bitwise_equal(ref, taylor(ScatterStrategy::Colored, 1, true)));
  const auto* x0 = reinterpret_cast<const Vec3*>(ref.at(col::x).data());
  for (ScatterStrategy st : {ScatterStrategy::LRSlabs, ScatterStrategy::ArrayExpansion}) {
    const ColumnStore other = taylor(st, 2, true);
    ASSERT_EQ(other.size(), ref.size()) << to_string(st) << ": the same particles split";
    const auto* x1 = reinterpret_cast<const Vec3*>(other.at(col::x).data());
    double dx = 0;
    for (std::size_t i = 0; i < ref.size(); ++i) dx = std::max(dx, (x1[i] - x0[i]).norm());
    EXPECT_LT(dx, 1e-12) << to_string(st) << ": m";
  }
}

// The sparse grid numbers cells in the dense window's order, so the particles sort into the
// same bins and chunks and every node sums its contributions in the same order: as long as
// both re-sort at the same steps (on the Taylor bar they do: no particle strays two cells from
// the material), the frames are the same bits, at 1 and 2 threads alike.
TEST(Strategies, SparseGridGivesTheDenseWindowsBits) {
  long dense_sorts = 0, sparse_sorts = 0;
  const ColumnStore dense = taylor(ScatterStrategy::Colored, 2, false, false, &dense_sorts);
  const ColumnStore sparse = taylor(ScatterStrategy::Colored, 2, false, true, &sparse_sorts);
  EXPECT_GT(dense_sorts, 5) << "the test should exercise re-sorting";
  EXPECT_EQ(sparse_sorts, dense_sorts);
  EXPECT_TRUE(bitwise_equal(dense, sparse));
  EXPECT_TRUE(bitwise_equal(sparse, taylor(ScatterStrategy::Colored, 1, false, true)));
}

}  // namespace
}  // namespace mpm
