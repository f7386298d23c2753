// HJC concrete through the tools: a compressed concrete cube runs with the damage and mu_max
// columns in its frames (and a scene without HJC has neither), and bad HJC input is refused
// with exit status 2 naming the file, the line and the key.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>

#include "run_command.hpp"

namespace mpm {
namespace {

using namespace mpm::testing;
namespace fs = std::filesystem;

// An eighth of a 20 mm cube under a frictionless platen at 0.5 m/s (tests/verification/
// test_hjc.cpp has the physics; here 2 mm cells, 120 us: past the crushing that starts at
// 30 us, so the damage has grown).
const char* kCube = R"([materials.concrete]
density = "2440 kg/m^3"
shear_modulus = "14.86 GPa"
[materials.concrete.strength]
model = "hjc"
A = 0.79
B = 1.60
N = 0.61
C = 0.007
fc = "48 MPa"
T = "4 MPa"
S_max = 7.0
D1 = 0.04
D2 = 1.0
EF_min = 0.01
[materials.concrete.eos]
model = "hjc"
P_crush = "16 MPa"
mu_crush = 0.001
P_lock = "0.80 GPa"
mu_lock = 0.10
K1 = "85 GPa"
K2 = "-171 GPa"
K3 = "208 GPa"
[[bodies]]
name = "cube"
material = "concrete"
shape = "box"
size = "10 10 10 mm"
translate = "5 5 5 mm"
velocity_field = ["7.27*x", "7.27*y", "-50*z"]
[[bodies]]
name = "platen"
rigid = true
slip = "x y"
shape = "box"
size = "13 13 2 mm"
translate = "6.5 6.5 11 mm"
velocity = "0 0 -0.5 m/s"
[grid]
cell_size = "2 mm"
domain = { min = "0 0 0 mm", max = "14 14 14 mm" }
[boundary]
x_min = "slip"
y_min = "slip"
z_min = "slip"
[solver]
end_time = "120 us"
[output]
frames = 2
)";

fs::path write(const fs::path& dir, const std::string& name, const std::string& text) {
  const fs::path p = dir / name;
  std::ofstream(p) << text;
  return p;
}

/// The largest value of column `col` in the last frame's particles CSV of `result`.
double column_max(const fs::path& result, const std::string& col, const fs::path& dir) {
  const Result r = run(post + " particles " + result.string() + " --columns " + col, dir);
  EXPECT_EQ(r.status, 0) << r.err;
  std::istringstream in(r.out);
  std::string line;
  double best = -1;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || !std::isdigit(line[0])) continue;
    best = std::max(best, std::stod(line.substr(line.rfind(',') + 1)));
  }
  return best;
}

TEST(HjcCli, CubeRunsWithDamageColumns) {
  const auto dir = temp_dir("hjc_cube");
  const fs::path scene = write(dir, "cube.toml", kCube);
  const Result r = prep_and_run(scene, "", dir / "cube.mpm", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  // Crushed past mu_crush = 0.001 (the pressure passed P_crush = 16 MPa) and damaged.
  EXPECT_GT(column_max(dir / "cube.mpm", "mu_max", dir), 0.001);
  const double D = column_max(dir / "cube.mpm", "damage", dir);
  EXPECT_GT(D, 0.0);
  EXPECT_LE(D, 1.0);
}

TEST(HjcCli, BadHjcInputExitsTwo) {
  const auto dir = temp_dir("hjc_bad");
  struct Case {
    std::string from, to, says;
  };
  const std::vector<Case> cases = {
      {"fc = \"48 MPa\"\n", "",
       "bad.toml:4: materials.concrete.strength: missing required key 'fc'"},
      {"D2 = 1.0", "D2 = -1.0", "bad.toml:14: materials.concrete.strength.D2: must be >= 0"},
      {"mu_lock = 0.10", "mu_lock = -0.1",
       "bad.toml:21: materials.concrete.eos.mu_lock: must be > 0"},
      {"model = \"hjc\"\nA", "model = \"j2\"\nA",
       "bad.toml:8: materials.concrete.strength.N: not used by this model"},
  };
  for (const auto& c : cases) {
    std::string text = kCube;
    const auto at = text.find(c.from);
    ASSERT_NE(at, std::string::npos) << c.from;
    text.replace(at, c.from.size(), c.to);
    const fs::path scene = write(dir, "bad.toml", text);
    const Result r = run(prep + " " + scene.string() + " -o " + (dir / "model.mpm").string(), dir);
    EXPECT_EQ(r.status, 2) << c.says << "\n" << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
  }
  // A bad value set on the command line of mpm-run, against a good model.
  const fs::path good = dir / "good.mpm";
  ASSERT_EQ(run(prep + " " + write(dir, "good.toml", kCube).string() + " -o " + good.string(), dir)
                .status,
            0);
  const Result r = run(runner + " " + good.string() +
                           " --progress none --set materials.concrete.strength.fc=-1 -o " +
                           (dir / "r.mpm").string(),
                       dir);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("materials.concrete.strength.fc: must be > 0"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace mpm
