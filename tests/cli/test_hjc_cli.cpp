// HJC concrete through the tools: a compressed concrete cube runs with the damage and mu_max
// columns in its frames (and a scene without HJC has neither), and bad HJC input is refused
// with exit status 2 naming the file, the line and the key.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <utility>

#include "run_command.hpp"

namespace mpm {
namespace {

using namespace mpm::testing;
namespace fs = std::filesystem;

// 004 Table 4's concrete (V5), the material of both scenes below.
const std::string kConcrete = R"([materials.concrete]
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
)";

// An eighth of a 20 mm cube under a frictionless platen at 0.5 m/s (tests/verification/
// test_hjc.cpp has the physics; here 2 mm cells, 120 us: past the crushing that starts at
// 30 us, so the damage has grown).
const std::string kCube = kConcrete + R"([[bodies]]
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
  double best = -1;
  for (const double x : read_csv(r.out).column(col)) best = std::max(best, x);
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

// An eighth of a 40 mm concrete cube expanding equally on all three axes at 1000 /s (velocity
// 1000 x, 1000 y, 1000 z; slip on the three symmetry planes), 2 us: by about 1.2 us its
// pressure K mu reaches the tension cut, which then holds it. Inside, 5 mm from the symmetry
// planes and 15 mm from the free faces (the release from them travels 7.7 mm in 2 us), no
// force acts, so each particle keeps its velocity and the rate of deformation is 1000 /
// (1 + 1000 t) /s on all three axes. The cut there at the last step: T = 4 MPa with HJC as
// published; with tension_rate = "malvar-ross", T x 14.199866584204333 (the factor at 1000 /s)
// x (rate / 1000)^(1/3) = 56.76165 MPa at t = 2 us, 56.76390 MPa at the last step's start
// (1.881 us): 56.7628 MPa +- 1.2 kPa; with tension_dif_max = 5, 20 MPa.
const std::string kExpanding = kConcrete + R"([[bodies]]
name = "cube"
material = "concrete"
shape = "box"
size = "20 20 20 mm"
translate = "10 10 10 mm"
velocity_field = ["1000*x", "1000*y", "1000*z"]
[grid]
cell_size = "1 mm"
domain = { min = "0 0 0 mm", max = "24 24 24 mm" }
[boundary]
x_min = "slip"
y_min = "slip"
z_min = "slip"
[solver]
end_time = "2 us"
[output]
frames = 1
)";

TEST(HjcCli, ExpandingCubeHoldsTheRateDependentTensionCut) {
  const auto dir = temp_dir("hjc_expanding");
  // The mean tension (sigma_xx = sigma_yy = sigma_zz, no deviator) of the particles within
  // 5 mm of the corner, least and most.
  const auto held = [&](const std::string& strength_keys) {
    std::string text = kExpanding;
    const std::string at = "EF_min = 0.01\n";
    text.replace(text.find(at), at.size(), at + strength_keys);
    const fs::path scene = write(dir, "cube.toml", text);
    const Result r = prep_and_run(scene, "", dir / "cube.mpm", dir);
    EXPECT_EQ(r.status, 0) << r.err;
    // mpm-prep says when the law is on, and what it gives.
    const bool law = strength_keys.find("malvar-ross") != std::string::npos;
    const bool capped = strength_keys.find("tension_dif_max") != std::string::npos;
    const std::string says =
        "tensile strength 4 MPa rising with the strain rate (Malvar-Ross for f'c 48 MPa): 5.68 "
        "MPa at 1 /s, " +
        std::string(capped ? "20 at 100 /s, 20 at 1000 /s, at most 20 MPa (x5)\n"
                           : "26.36 at 100 /s, 56.8 at 1000 /s\n");
    EXPECT_EQ(r.err.find(says) != std::string::npos, law) << r.err;
    const Result csv = run(
        post + " particles " + (dir / "cube.mpm").string() + " --columns x,sigma --digits 12", dir);
    EXPECT_EQ(csv.status, 0) << csv.err;
    double lo = 1e300, hi = -1e300;
    int n = 0;
    for (const auto& v : read_csv(csv.out).rows) {
      EXPECT_EQ(v.size(), 9u);  // x_0..2, sigma_0..5
      if (v.size() < 9) continue;
      if (v[0] > 5e-3 || v[1] > 5e-3 || v[2] > 5e-3) continue;
      EXPECT_EQ(v[3], v[4]);
      EXPECT_EQ(v[3], v[5]);
      lo = std::min(lo, v[3]), hi = std::max(hi, v[3]), ++n;
    }
    EXPECT_GT(n, 100);
    return std::pair{lo, hi};
  };
  const auto plain = held("");
  EXPECT_NEAR(plain.first, 4e6, 1.0);
  EXPECT_NEAR(plain.second, 4e6, 1.0);
  const auto rate = held("tension_rate = \"malvar-ross\"\n");
  EXPECT_NEAR(rate.first, 56.7628e6, 1.2e3);
  EXPECT_NEAR(rate.second, 56.7628e6, 1.2e3);
  const auto capped = held("tension_rate = \"malvar-ross\"\ntension_dif_max = 5\n");
  EXPECT_NEAR(capped.first, 20e6, 5.0);
  EXPECT_NEAR(capped.second, 20e6, 5.0);
}

// The averaged damage (damage_length, docs/scene.md) on the crushed cube: at the cell size
// (2 mm: 8 particles a lattice cell) and at 6 mm (three cells) the damage evens out more the
// longer the length, each run the same at one and two threads, bit for bit (a particle alone
// in its lattice cell keeps its own increment: tests/unit/test_damage_average.cpp).
TEST(HjcCli, AveragedDamageEvensOutWithItsLengthWhateverTheThreads) {
  const auto dir = temp_dir("hjc_nonlocal");
  // Damage by particle id after a run with `keys` added to the strength table.
  const auto damage = [&](const std::string& keys, const std::string& threads) {
    std::string text = kCube;
    const std::string at = "EF_min = 0.01\n";
    text.replace(text.find(at), at.size(), at + keys);
    const fs::path scene = write(dir, "cube.toml", text);
    const Result r =
        run(prep + " " + scene.string() + " | " + runner + " --progress none --threads " + threads +
                " -o " + (dir / "cube.mpm").string(),
            dir);
    EXPECT_EQ(r.status, 0) << r.err;
    if (!keys.empty())  // mpm-prep says the damage is averaged, and over what
      EXPECT_NE(r.err.find(keys == "damage_length = \"2 mm\"\n"
                               ? "damage increments averaged over 2 mm (1 finest cells; "
                                 "reaching at most 4 mm each way)"
                               : "damage increments averaged over 6 mm (3 finest cells; "
                                 "reaching at most 12 mm each way)"),
                std::string::npos)
          << r.err;
    const Result csv = run(post + " particles " + (dir / "cube.mpm").string() +
                               " --columns id,body,damage --digits 17",
                           dir);
    EXPECT_EQ(csv.status, 0) << csv.err;
    std::map<long, double> by_id;
    for (const auto& v : read_csv(csv.out).rows)
      if (v.size() >= 3 && v[1] == 0) by_id[long(v[0])] = v[2];  // the cube's (body 0)
    return by_id;
  };
  const auto local = damage("", "1");
  const auto cell = damage("damage_length = \"2 mm\"\n", "1");
  const auto wide = damage("damage_length = \"6 mm\"\n", "1");
  const auto wide2 = damage("damage_length = \"6 mm\"\n", "2");
  for (const auto& [id, D] : wide) EXPECT_EQ(wide2.at(id), D) << id;  // bitwise
  // The averaged increments keep their mass-weighted sum each step (damage_average.hpp; the
  // cube's particles have equal masses), so the mean damage moves only through the feedback
  // of a slightly different field (2e-5 here); the spread over the particles (standard
  // deviation about the mean) shrinks (to 0.53 of the local one: the crushing is nearly uniform,
  // the spread is the platen's edge and the free faces').
  const auto spread = [](const std::map<long, double>& d, double& mean) {
    double s = 0, s2 = 0;
    for (const auto& [id, D] : d) s += D, s2 += D * D;
    mean = s / double(d.size());
    return std::sqrt(std::max(0.0, s2 / double(d.size()) - mean * mean));
  };
  double mean_local, mean_cell, mean_wide;
  const double sd_local = spread(local, mean_local), sd_cell = spread(cell, mean_cell),
               sd_wide = spread(wide, mean_wide);
  std::printf("damage: local mean %.6g sd %.4g; 2 mm %.6g %.4g; 6 mm %.6g %.4g\n", mean_local,
              sd_local, mean_cell, sd_cell, mean_wide, sd_wide);
  ASSERT_EQ(local.size(), 1000u);
  ASSERT_GT(mean_local, 0.1);
  EXPECT_NEAR(mean_cell, mean_local, 1e-3 * mean_local);
  EXPECT_NEAR(mean_wide, mean_local, 1e-3 * mean_local);
  EXPECT_LT(sd_cell, sd_local);
  EXPECT_LT(sd_wide, 0.75 * sd_local);
  EXPECT_LT(sd_wide, sd_cell);
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
      // The opt-in rate-dependent tensile strength: a law it knows, a cap of at least 1, and
      // the cap only with a law.
      {"EF_min = 0.01\n", "EF_min = 0.01\ntension_rate = \"fast\"\n",
       "bad.toml:16: materials.concrete.strength.tension_rate: expected one of \"none\", "
       "\"malvar-ross\", got 'fast'"},
      {"EF_min = 0.01\n", "EF_min = 0.01\ntension_rate = \"malvar-ross\"\ntension_dif_max = 0.5\n",
       "bad.toml:17: materials.concrete.strength.tension_dif_max: must be at least 1"},
      {"EF_min = 0.01\n", "EF_min = 0.01\ntension_dif_max = 8\n",
       "bad.toml:16: materials.concrete.strength.tension_dif_max: caps the rate law of "
       "tension_rate; set tension_rate = \"malvar-ross\" too"},
      {"EF_min = 0.01\n", "EF_min = 0.01\ndamage_length = \"0 mm\"\n",
       "bad.toml:16: materials.concrete.strength.damage_length: must be > 0"},
      {"EF_min = 0.01\n", "EF_min = 0.01\ndamage_length = \"4 MPa\"\n",
       "bad.toml:16: materials.concrete.strength.damage_length:"},
      {"EF_min = 0.01\n", "EF_min = 0.01\ndamage_length = \"1 mm\"\n",
       "bad.toml:16: materials.concrete.strength.damage_length: expected at least the finest "
       "cell, 2 mm (a few cells for the average to act), got 1 mm"},
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

// examples/rc-slab/axisym.toml is V5's projectile and slab in axisymmetry: the ogive on the axis
// (25 mm across, so that the particles' lattices tile its shank) with the density that keeps the
// 3D scene's exact projectile mass, 0.514 kg whole, and the particles' mass within 0.2% of it.
TEST(HjcCli, AxisymmetricV5KeepsTheQuarterModelsProjectileMass) {
  const auto dir = temp_dir("hjc_axisym_v5");
  const std::string ex = std::string(MPM_EXAMPLES) + "/rc-slab/";
  // The "projectile" row of mpm-prep's mass table: particles' mass and exact mass, kg.
  const auto masses = [&](const std::string& args) {
    const Result r = run(prep + " " + args + " -o /dev/null", dir);
    EXPECT_EQ(r.status, 0) << r.err;
    const auto at = r.err.find("\n  projectile ");
    EXPECT_NE(at, std::string::npos) << r.err;
    std::pair<double, double> m{0, 0};
    const auto kg = r.err.find(" mm ", at);  // after the spacing
    if (at != std::string::npos && kg != std::string::npos)
      std::sscanf(r.err.c_str() + kg + 4, "%lf %lf", &m.first, &m.second);
    return m;
  };
  const auto whole = masses(ex + "scene.toml --set grid.cell_size=16mm");
  EXPECT_NEAR(whole.second, 0.514443, 1e-6);
  for (const char* path : {"", " --set bodies.projectile.particles_per_cell=2"}) {
    const auto axi = masses(ex + "axisym.toml" + path);  // per radian
    EXPECT_NEAR(2 * M_PI * axi.second / whole.second, 1.0, 1e-5) << path;
    EXPECT_NEAR(axi.first / axi.second, 1.0, 2e-3) << path;
  }
}

}  // namespace
}  // namespace mpm
