// mpm-prep --target-error (issue 22): on the axisymmetric Taylor bar of examples/trade the
// proposed model's run is within the target against the experiment and costs what was
// predicted; scenes without a fit and unreachable targets are refused with exit status 2.
#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <string>

#include "run_command.hpp"

namespace mpm {
namespace {

using namespace mpm::testing;
namespace fs = std::filesystem;

const std::string kBar = std::string(MPM_EXAMPLES) + "/trade/taylor_axi.toml";

double number_after(const std::string& text, const std::string& pattern) {
  std::smatch m;
  if (!std::regex_search(text, m, std::regex(pattern + "([-+0-9.eE]+)"))) return NAN;
  return std::stod(m[1]);
}

// The 2% proposal, run: L and D on the surface within 2% of the experiment (16.2 and 13.5
// mm), and its particle-steps within a factor 1.5 of the prediction (the bound; the
// prediction is mpm-prep's step estimate times the particles, about 4% high on this bar).
TEST(TargetError, TaylorBarProposalReachesTheTargetAtThePredictedCost) {
  const auto dir = temp_dir("target_error_taylor");
  const Result p =
      run(prep + " " + kBar + " --target-error 2% -o " + (dir / "model.mpm").string(), dir);
  ASSERT_EQ(p.status, 0) << p.err;
  const double predicted = number_after(p.err, "predicted cost ");
  ASSERT_TRUE(predicted > 0) << p.err;
  const Result r =
      run(runner + " " + (dir / "model.mpm").string() + " --threads 1 --stats --progress none -o " +
              (dir / "result.mpm").string(),
          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const double measured = number_after(r.err, "particle-steps ");
  EXPECT_LT(measured / predicted, 1.5) << r.err;
  EXPECT_GT(measured / predicted, 1 / 1.5) << r.err;
  const Result t =
      run(post + " taylor " + (dir / "result.mpm").string() + " --surface --json", dir);
  ASSERT_EQ(t.status, 0) << t.err;
  EXPECT_LE(std::abs(json_value(t.out, "L") / 16.2e-3 - 1), 0.02) << t.out;
  EXPECT_LE(std::abs(json_value(t.out, "D") / 13.5e-3 - 1), 0.02) << t.out;
}

// Below the axisymmetric model's converged error against the experiment (D about 1.3% narrow)
// no cell size helps: exit 2 with the floor. A bar at another speed is not similar to V2 and a
// wave rod is no Taylor bar: no fit, exit 2, naming what differs. A malformed value: exit 2.
TEST(TargetError, NoFitOrUnreachableTargetIsRefused) {
  const auto dir = temp_dir("target_error_refused");
  Result r = run(prep + " " + kBar + " --target-error 1% -o " + (dir / "m.mpm").string(), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("converged error against the experiment"), std::string::npos) << r.err;
  r = run(prep + " " + kBar + " --set bodies.bar.velocity=\"0 -250 m/s\" --target-error 5% -o " +
              (dir / "m.mpm").string(),
          dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("no fit for this scene: density speed^2 / A"), std::string::npos) << r.err;
  r = run(prep + " " + std::string(MPM_EXAMPLES) + "/wave-rod/graded.toml --target-error 5% -o " +
              (dir / "m.mpm").string(),
          dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("no fit for this scene"), std::string::npos) << r.err;
  r = run(prep + " " + kBar + " --target-error two -o " + (dir / "m.mpm").string(), dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("expected a percentage"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace mpm
