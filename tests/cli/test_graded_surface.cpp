// mpm-post taylor --surface on a graded grid (issue 22): the foot lies on the fine level, whose
// particles split to half the spacing, so its surface is half a fine spacing outside the
// centres on each side; the model's (coarse) spacing overstated D by a fine spacing.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "run_command.hpp"

namespace mpm {
namespace {

using namespace mpm::testing;

// The axisymmetric Taylor bar of examples/trade on 0.76 mm cells with a level-2 box (0.38 mm
// cells, spacing 0.19 mm) over the 3.8 mm by the wall: D on the surface is the centres' D plus
// 0.19 mm, L the centres' L plus half the coarse spacing, 0.19 mm; and the first frame's
// surface measures are the bar's true length and diameter to within half a coarse spacing
// (its length, 25.4 mm, is tiled by whole spacings: 25.46 mm) and exactly (7.6 mm = 20 x 0.38).
TEST(GradedSurface, TaylorSurfaceUsesTheSpacingOfTheLevel) {
  const auto dir = temp_dir("graded_surface");
  const std::string scene = std::string(MPM_EXAMPLES) + "/trade/taylor_axi.toml";
  const std::string result = (dir / "r.mpm").string();
  const Result r =
      run(prep + " " + scene +
              " -q --set solver.end_time=\"20 us\" --set grid.levels=\"[{ level = 2, min = "
              "\\\"0 0 mm\\\", max = \\\"7.6 3.8 mm\\\" }]\" | " +
              runner + " --threads 1 --progress none -o " + result,
          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const Result c = run(post + " taylor " + result + " --json", dir);
  const Result s = run(post + " taylor " + result + " --json --surface", dir);
  ASSERT_EQ(s.status, 0) << s.err;
  const double tol = 1e-9;  // m: the measures are sums of the same doubles
  EXPECT_NEAR(json_value(s.out, "D") - json_value(c.out, "D"), 0.19e-3, tol) << s.out;
  EXPECT_NEAR(json_value(s.out, "L") - json_value(c.out, "L"), 0.19e-3, tol) << s.out;
  EXPECT_NEAR(json_value(s.out, "D0"), 7.6e-3, tol) << s.out;
  EXPECT_NEAR(json_value(s.out, "L0"), 25.4e-3, 0.19e-3) << s.out;
}

}  // namespace
}  // namespace mpm
