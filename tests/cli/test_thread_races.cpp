// A race check of the OpenMP kernels by differences (ThreadSanitizer reports false races
// inside GCC's libgomp): every scatter strategy on every kind of grid, and the implicit
// solver, run with the real binaries at 1 thread and at 2 threads three times. A race shows
// as 2-thread runs that differ from each other, or, for the colored strategy (the
// --deterministic one, and the implicit solver's scatters), from the 1-thread run: these must
// be bitwise equal, frame by frame. The other strategies sum nodes in another order at 2
// threads, so they agree with 1 thread to round-off only. OMP_WAIT_POLICY=passive: two
// spinning threads on a loaded machine make the runs many times slower.
#include <gtest/gtest.h>

#include <filesystem>

#include "mpm/core/types.hpp"
#include "mpm/stream/stream.hpp"
#include "run_command.hpp"

namespace mpm {
namespace {

using namespace mpm::testing;
namespace fs = std::filesystem;

/// The frames of a result stream, in order.
std::vector<Frame> frames_of(const fs::path& p) {
  std::vector<Frame> out;
  StreamVisitor v;
  v.frame = [&](Frame&& f) { out.push_back(std::move(f)); };
  const StreamSummary s = read_stream(p.string(), v);
  EXPECT_TRUE(s.damage.empty()) << s.damage;
  EXPECT_TRUE(s.ended && s.end_status == 0) << p << ": " << s.end_message;
  return out;
}

bool bitwise_equal(const std::vector<Frame>& a, const std::vector<Frame>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t k = 0; k < a.size(); ++k) {
    const ColumnStore &p = a[k].columns, &q = b[k].columns;
    if (a[k].step != b[k].step || p.size() != q.size() || p.columns().size() != q.columns().size())
      return false;
    for (const Column& c : p.columns()) {
      const Column* d = q.find(c.info().name);
      if (!d || d->bytes() != c.bytes() || std::memcmp(c.data(), d->data(), c.bytes()) != 0)
        return false;
    }
  }
  return true;
}

/// Largest distance between the particles' final positions of two runs (m), by particle id.
double position_difference(const std::vector<Frame>& a, const std::vector<Frame>& b) {
  const ColumnStore &p = a.back().columns, &q = b.back().columns;
  EXPECT_EQ(p.size(), q.size());
  const int D = int(p.at("x").info().components);
  const auto* id_p = p.get<std::uint32_t>("id");
  const auto* id_q = q.get<std::uint32_t>("id");
  const auto* x_p = reinterpret_cast<const double*>(p.at("x").data());
  const auto* x_q = reinterpret_cast<const double*>(q.at("x").data());
  // Particles that left the domain are gone from the frame: ids run past its size.
  std::uint32_t ids = 0;
  for (std::size_t i = 0; i < q.size(); ++i) ids = std::max(ids, id_q[i] + 1);
  std::vector<std::size_t> at(ids, q.size());
  for (std::size_t i = 0; i < q.size(); ++i) at[id_q[i]] = i;
  double worst = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (id_p[i] >= ids || at[id_p[i]] == q.size()) return INFINITY;  // not in the other run
    for (int d = 0; d < D; ++d)
      worst = std::max(worst, std::abs(x_p[i * D + d] - x_q[at[id_p[i]] * D + d]));
  }
  return worst;
}

struct Case {
  std::string name, scene, sets;        ///< scene file and --set options for mpm-prep
  std::vector<std::string> strategies;  ///< empty: the solver has no --strategy (implicit)
  std::string run_sets = "";            ///< options for mpm-run
};

/// Runs each strategy of a case at 1 thread, then at 2 threads three times.
void check(const Case& c) {
  const fs::path dir = temp_dir("races_" + c.name), model = dir / "model.mpm";
  ASSERT_EQ(run(prep + " " + c.scene + " " + c.sets + " -o " + model.string(), dir).status, 0);
  const std::vector<std::string> strategies =
      c.strategies.empty() ? std::vector<std::string>{""} : c.strategies;
  for (const std::string& s : strategies) {
    const std::string opt = s.empty() ? "" : " --strategy " + s;
    auto run_with = [&](int threads, int k) {
      const fs::path out = dir / (s + std::to_string(threads) + "_" + std::to_string(k) + ".mpm");
      const Result r = run("OMP_WAIT_POLICY=passive " + runner + " " + model.string() +
                               " --progress none --threads " + std::to_string(threads) + opt + " " +
                               c.run_sets + " -o " + out.string(),
                           dir);
      EXPECT_EQ(r.status, 0) << c.name << " " << s << ": " << r.err;
      return out;
    };
    const std::vector<Frame> one = frames_of(run_with(1, 0));
    ASSERT_GE(one.size(), 2u);
    const std::vector<Frame> first_two = frames_of(run_with(2, 0));
    if (s.empty() || s == "colored") {
      EXPECT_TRUE(bitwise_equal(first_two, one)) << c.name << " " << s << ": 2 threads against 1";
    }
    for (int k = 1; k < 3; ++k) {
      EXPECT_TRUE(bitwise_equal(frames_of(run_with(2, k)), first_two))
          << c.name << " " << s << ": 2-thread run " << k << " against the first";
    }
    // Only the order of the sums differs: positions agree to round-off amplified by the steps
    // (measured below 1e-15 m on these mm-sized bodies; a misplaced contribution moves a
    // particle by far more than 1e-12 m, which is 1e-9 of a cell).
    EXPECT_LT(position_difference(first_two, one), 1e-12) << c.name << " " << s;
  }
}

const std::string kData = std::string(MPM_TEST_DATA) + "/cli/";
const std::string kExamples = std::string(MPM_EXAMPLES) + "/";

TEST(ThreadRaces, UniformGridEveryStrategy) {
  check({"uniform",
         kData + "taylor_restart.toml",
         "",
         {"colored", "lr-slabs", "array-expansion", "patch"}});
}

TEST(ThreadRaces, SparseGridEveryStrategy) {
  check({"sparse",
         kData + "taylor_restart.toml",
         "--set grid.sparse=true",
         {"colored", "lr-slabs", "array-expansion"}});
}

// Particles that leave the domain (escape records, written from the per-thread lists).
TEST(ThreadRaces, EscapingParticlesEveryStrategy) {
  check({"escape", kData + "escape.toml", "", {"colored", "lr-slabs", "array-expansion", "patch"}});
}

// The graded Taylor bar: transition cells, hanging nodes, particles split by the wall.
TEST(ThreadRaces, GradedGridEveryStrategy) {
  check({"graded",
         kExamples + "taylor-bar/graded.toml",
         "--set grid.cell_size=\"0.76 mm\" --set solver.end_time=\"1 us\"",
         {"colored", "lr-slabs", "array-expansion"}});
}

// Axisymmetric 2D: V4's sphere into a plate at 2.12 mm cells, the first 3 us of the impact
// (on the sparse grid, which has no patch strategy).
TEST(ThreadRaces, AxisymmetricEveryStrategy) {
  check({"axisym",
         kExamples + "hypervelocity/axisym.toml",
         "--set solver.end_time=\"3 us\"",
         {"colored", "lr-slabs", "array-expansion"}});
}

// The implicit solver (colored scatters, Newton-Krylov's reductions by chunk) on V7's disks.
TEST(ThreadRaces, ImplicitSolver) {
  check({"implicit",
         kExamples + "implicit/disks.toml",
         "--set solver.end_time=20",
         {},
         "--set solver.type=implicit"});
}

}  // namespace
}  // namespace mpm
