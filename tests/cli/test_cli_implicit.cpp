// The implicit solver through the tools: chosen by the scene (or --set at mpm-run), its history
// columns, bad keys (exit 2), and a Newton failure that cutting the step cannot rescue (exit 3,
// the frames before it stay valid). Also mpm-post particles.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

#include "run_command.hpp"

namespace mpm {
namespace {

using namespace mpm::testing;
namespace fs = std::filesystem;

const fs::path kBlock = fs::path(MPM_TEST_DATA) / "cli" / "block.toml";

TEST(CliImplicit, RunsAndWritesItsWorkToTheHistory) {
  const auto dir = temp_dir("implicit_run");
  const fs::path out = dir / "run.mpm";
  Result r =
      run(prep + " " + kBlock.string() + " | " + runner +
              " --threads 1 --progress none --stats --set solver.type=implicit -o " + out.string(),
          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("implicit: explicit dt"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("stress_trial"), std::string::npos) << "kernel timers" << r.err;
  r = run(post + " history " + out.string() +
              " --columns step,dt_multiple,newton,krylov,residual_evals,line_search_cuts,"
              "step_cuts,residual_evals_total",
          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  // The per-row counts add up to the last row's total.
  const Csv csv = read_csv(r.out);
  ASSERT_EQ(csv.names.size(), 8u);
  double sum = 0, total = 0;
  for (const auto& v : csv.rows) {
    ASSERT_EQ(v.size(), 8u);
    sum += v[4];
    total = v[7];
  }
  EXPECT_GT(csv.rows.size(), 3u);
  EXPECT_GT(total, 0);
  EXPECT_EQ(sum, total);
}

TEST(CliImplicit, BadKeysAreInputErrors) {
  const auto dir = temp_dir("implicit_bad");
  Result r = run(prep + " " + kBlock.string() +
                     " --set solver.type=implicit --set solver.implicit.theta=2 >/dev/null",
                 dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--set solver.implicit.theta: must be between 0"), std::string::npos)
      << r.err;
  r = run(prep + " " + kBlock.string() + " --set solver.implicit.theta=0.5 >/dev/null", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("is used only with solver.type = \"implicit\""), std::string::npos) << r.err;
}

// The block falls 2 mm to the wall: free flight needs no Newton iteration (a translation has
// no residual beyond round-off, ~1e-14), the impact does, and one iteration cannot meet a
// tolerance of 1e-10 there; two cuts do not rescue it, so the run stops like an instability.
TEST(CliImplicit, NewtonFailureStopsTheRunAndKeepsItsFrames) {
  const auto dir = temp_dir("implicit_fail");
  const fs::path out = dir / "run.mpm";
  Result r =
      run(prep + " " + kBlock.string() +
              " --set bodies.block.translate=\"0 0 4 mm\" --set solver.end_time=\"40 us\"" +
              " --set output.frames=40 | " + runner +
              " --threads 1 --progress none --set solver.type=implicit" +
              " --set solver.implicit.max_newton=1 --set solver.implicit.newton_tolerance=1e-10" +
              " --set solver.implicit.max_cuts=2 --set solver.implicit.dt_target_multiple=10" +
              " -o " + out.string(),
          dir);
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("did not converge after 2 cuts"), std::string::npos) << r.err;
  r = run(post + " summary " + out.string() + " --json", dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("\"status\": 3"), std::string::npos) << r.out;
  // Frames of the free flight were written before the failure.
  const auto frames = std::count(r.out.begin(), r.out.end(), '{') - 1;
  EXPECT_GE(frames, 3) << r.out;
}

TEST(CliImplicit, PostParticlesWritesCsv) {
  const auto dir = temp_dir("post_particles");
  const fs::path out = dir / "run.mpm";
  Result r = run(prep + " " + kBlock.string() + " | " + runner +
                     " --threads 1 --progress none -o " + out.string(),
                 dir);
  ASSERT_EQ(r.status, 0) << r.err;
  r = run(post + " particles " + out.string() + " --columns id,x,sigma --frame 0", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  std::istringstream lines(r.out);
  std::string comment, units, header, row;
  std::getline(lines, comment);
  std::getline(lines, units);
  std::getline(lines, header);
  EXPECT_EQ(comment.rfind("# t = 0 s", 0), 0u) << comment;
  EXPECT_EQ(units, "# units: -,m,m,m,Pa,Pa,Pa,Pa,Pa,Pa");
  EXPECT_EQ(header, "id,x_0,x_1,x_2,sigma_0,sigma_1,sigma_2,sigma_3,sigma_4,sigma_5");
  long n = 0;
  while (std::getline(lines, row)) ++n;
  EXPECT_EQ(n, 4 * 4 * 4 * 8);  // 4 mm cube, 1 mm cells, 2 x 2 x 2 per cell
  r = run(post + " particles " + out.string() + " --columns nope", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("unknown particle column 'nope'"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace mpm
