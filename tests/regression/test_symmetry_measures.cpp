// Quarter and half models measured as the whole body: the Taylor bar example run whole, as a
// half (slip on x_min through the bar) and as a quarter (slip on x_min and y_min), at coarse
// 1.52 mm cells. mpm-post taylor must find the mirror planes in the stored scene and report the
// whole bar's L and D.
#include <gtest/gtest.h>

#include "cli/run_command.hpp"

namespace mpm {
namespace {

using namespace mpm::testing;
namespace fs = std::filesystem;

/// The example at 1.52 mm cells on a domain whose faces x = 0 and y = 0 are cell faces (so the
/// lattice of the half and the quarter is the whole model's, cut), from `lo` in x and y.
std::string coarse_taylor(const std::string& lo, const std::string& faces) {
  return "--set grid.cell_size=\"1.52 mm\" --set grid.domain.min=\"" + lo +
         " 0 mm\" --set grid.domain.max=\"12.16 12.16 27.36 mm\"" + faces;
}

/// The scene with `args` through mpm-prep and mpm-run (one thread: the models are small) to `out`.
Result prep_run(const fs::path& scene, const std::string& args, const fs::path& out,
                const fs::path& dir) {
  return run(prep + " " + scene.string() + " " + args + " | " + runner +
                 " --threads 1 --progress none -o " + out.string(),
             dir);
}

double json_of(const std::string& command, const std::string& key, const fs::path& dir) {
  const Result r = run(command, dir);
  EXPECT_EQ(r.status, 0) << r.err;
  return json_value(r.out, key);
}

TEST(Symmetry, QuarterAndHalfTaylorBarsMeasureAsTheWholeBar) {
  const auto dir = temp_dir("symmetry_taylor");
  const fs::path scene = fs::path(MPM_EXAMPLES) / "taylor-bar" / "scene.toml";
  const fs::path whole = dir / "whole.mpm", half = dir / "half.mpm", quarter = dir / "quarter.mpm";
  Result r = prep_run(scene, coarse_taylor("-12.16 -12.16", ""), whole, dir);
  ASSERT_EQ(r.status, 0) << r.err;
  r = prep_run(scene, coarse_taylor("0 -12.16", " --set boundary.x_min=slip"), half, dir);
  ASSERT_EQ(r.status, 0) << r.err;
  r = prep_run(scene, coarse_taylor("0 0", " --set boundary.x_min=slip --set boundary.y_min=slip"),
               quarter, dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string taylor = post + " taylor --json ";
  const double L = json_of(taylor + whole.string(), "L", dir);
  const double D = json_of(taylor + whole.string(), "D", dir);
  ASSERT_GT(D, 10e-3);  // the foot spread: 7.6 mm across at the start
  // The slip faces stand where the whole model's mirror planes are: the half and the quarter
  // are the whole model cut, to round-off (the sums at the nodes on the planes run in another
  // order), so 0.1% (the bound) leaves a wide margin.
  for (const fs::path& part : {half, quarter}) {
    r = run(taylor + part.string(), dir);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NEAR(json_value(r.out, "L"), L, 1e-3 * L) << part << r.out;
    EXPECT_NEAR(json_value(r.out, "D"), D, 1e-3 * D) << part << r.out;
    EXPECT_NE(r.out.find("\"source\": \"scene\""), std::string::npos) << r.out;
    EXPECT_EQ(json_value(r.out, "images"), part == half ? 2 : 4) << r.out;
  }
  // The text report says what it did; measured as it is, the quarter's foot is about half.
  r = run(post + " taylor " + quarter.string(), dir);
  EXPECT_NE(r.out.find("whole body from mirror planes x = 0 mm, y = 0 mm"), std::string::npos)
      << r.out;
  const double D_cut = json_of(taylor + quarter.string() + " --symmetry none", "D", dir);
  EXPECT_LT(D_cut, 0.6 * D);
  // The same planes given explicitly, and a bad one.
  EXPECT_NEAR(json_of(taylor + quarter.string() + " --symmetry \"x = 0, y = 0 mm\"", "D", dir), D,
              1e-3 * D);
  r = run(post + " taylor " + quarter.string() + " --symmetry \"z = 1 s\"", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--symmetry"), std::string::npos) << r.err;
  // The whole model declares no plane: its wall z = 0 carries the bar, it does not cut it.
  r = run(taylor + whole.string(), dir);
  EXPECT_NE(r.out.find("\"source\": \"none\""), std::string::npos) << r.out;
}

}  // namespace
}  // namespace mpm
