// HJC concrete (004 Table 4, V5) in a run: the scene keys of docs/scene.md parse to the
// published constants, a cube compressed between a frictionless platen and symmetry planes
// peaks at the model's unconfined strength (above f'c), and bad HJC input names its key.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>

#include "mpm/core/error.hpp"
#include "mpm/grid/lattice.hpp"
#include "mpm/prep/voxelise.hpp"
#include "mpm/solver/explicit/explicit_solver.hpp"

namespace mpm {
namespace {

/// The material block of docs/scene.md (HJC concrete, Hanchak's 48 MPa concrete), read from
/// the documentation so that the block the lead pastes is the one tested; after a blank line,
/// so that its keys sit on the lines the error cases name.
std::string concrete_block() {
  std::ifstream in(std::string(MPM_TEST_DATA) + "/../../docs/scene.md");
  EXPECT_TRUE(in.good()) << "docs/scene.md not found";
  std::string line, block = "\n";
  bool section = false, inside = false;
  while (std::getline(in, line)) {
    if (line == "### HJC concrete") section = true;
    if (section && !inside && line == "```toml") {
      inside = true;
    } else if (inside && line == "```") {
      break;
    } else if (inside) {
      block += line + "\n";
    }
  }
  EXPECT_NE(block.find("[materials.concrete.eos]"), std::string::npos) << block;
  return block;
}
const std::string kConcrete = concrete_block();

// An eighth of a 20 mm cube (x, y, z >= 0 on slip faces: symmetry planes) under a rigid
// frictionless platen moving down at 0.5 m/s on its top face z = 10 mm: uniaxial stress at
// 50 /s. The cube starts in that straining (v_z = -50 z, v_x,y = nu 50 x,y with nu = 0.1454),
// so the platen's arrival sends no wave; 1 mm cells, 2 x 2 x 2 particles per cell.
const std::string kCube = kConcrete + R"(
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
cell_size = "1 mm"
domain = { min = "0 0 0 mm", max = "14 14 14 mm" }
[boundary]
x_min = "slip"
y_min = "slip"
z_min = "slip"
[solver]
end_time = "160 us"
)";

TEST(HjcRun, SceneKeysGiveThePublishedConstants) {
  const Scene s = parse_scene(kCube, "cube.toml", "", {});
  const MaterialSpec& m = s.materials.at(0);
  EXPECT_EQ(m.strength.model, StrengthModel::Hjc);
  EXPECT_EQ(m.eos.model, EosModel::Hjc);
  EXPECT_DOUBLE_EQ(m.hjc.fc, 48e6);
  EXPECT_DOUBLE_EQ(m.hjc.T, 4e6);
  EXPECT_DOUBLE_EQ(m.hjc.P_lock, 0.8e9);
  EXPECT_DOUBLE_EQ(m.hjc.K2, -171e9);
  EXPECT_DOUBLE_EQ(m.hjc.reference_rate, 1.0);
  // G as given, K = P_crush / mu_crush = 16 GPa (E and nu follow from them).
  EXPECT_NEAR(m.shear_modulus(), 14.86e9, 1e-3);  // round-off of E and nu
  EXPECT_NEAR(m.bulk_modulus(), 16e9, 1e-3);
}

// Uniaxial stress in HJC: P = sigma / 3, so the concrete yields where sigma = f'c (A (1 - D) +
// B (sigma / 3 f'c)^N)(1 + C ln rate*). Before it yields it crushes (P passes P_crush = 16 MPa
// at sigma = 48 MPa), and the plastic volumetric strain of the crushing damages it: integrating
// dD = d mu_p / (D1 (P* + T*)) along P = sigma / 3 by hand (steps of 10 kPa) gives D = 0.064
// at first yield and sigma = 99.1 MPa at the equivalent deviatoric rate of the elastic phase,
// 2/3 (1 + nu) 50 /s = 38 /s (99.4 MPa at 50 /s, 95.4 MPa without the rate term). That is
// 2.06 f'c: with Table 4's A, B and N the unconfined strength is A + B (1/3)^N = 1.61 f'c
// even without damage at P* = 1/3, and 2.06 f'c where sigma* and P* agree; the model as
// published. After the peak the damage from plastic strain softens the cube.
TEST(HjcRun, CubeInUnconfinedCompressionPeaksAtTheModelsStrength) {
  const Scene scene = parse_scene(kCube, "cube.toml", "", {});
  const Lattice lat = make_lattice(scene);
  std::vector<BodyReport> report;
  ColumnStore cols = voxelise(scene, lat, report);
  UniformSolver<3> solver(scene, UniformGrid<3>(lat, scene.boundary), cols);
  // One thread: 8000 particles are too few to share, and two spinning threads on a loaded
  // machine ran this 80 times slower.
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  double peak = 0, strain_at_peak = 0, last = 0, D_max = 0;
  while (solver.time() < scene.solver.end_time * (1 - 1e-12)) {
    solver.step(std::min(solver.stable_dt(), scene.solver.end_time - solver.time()));
    const ParticleView<3> p = view<3>(cols);
    double V = 0, sz = 0;
    for (std::size_t i = 0; i < p.n; ++i) {
      if (p.body[i] != 0) continue;
      const double v = p.m[i] / p.rho[i];
      V += v;
      sz += -p.sigma[i][2] * v;  // compression positive
      D_max = std::max(D_max, p.damage[i]);
    }
    last = sz / V;
    if (last > peak) peak = last, strain_at_peak = 50.0 * solver.time();
  }
  omp_set_num_threads(threads);
  // The peak within 4% of 99.1 MPa: the rate term is uncertain by 0.3% (38 to 50 /s), the
  // stress ringing from the discrete start and the particles' own noise by a few percent.
  // Measured: 100.7 MPa at a strain of 0.0036 (100.6 MPa on 2 mm cells); without the
  // crushing's damage the fixed point would be 101.8 MPa, without the rate term 95.4 MPa.
  std::printf("HJC cube: %ld steps, peak %.4g MPa at strain %.4g, end %.4g MPa, D_max %.3f\n",
              long(solver.steps()), peak / 1e6, strain_at_peak, last / 1e6, D_max);
  EXPECT_NEAR(peak, 99.1e6, 0.04 * 99.1e6) << "strain at the peak " << strain_at_peak;
  EXPECT_GT(peak, 48e6);  // it reaches f'c
  // Past the peak it softens (damage from plastic strain) and damage has grown past the
  // 0.064 of the crushing before yield.
  EXPECT_LT(last, 0.95 * peak) << last;
  EXPECT_GT(D_max, 0.1);
}

/// what() of the InputError parsing `text` throws (a test failure if none).
std::string error_of(const std::string& text) {
  try {
    parse_scene(text, "bad.toml", "", {});
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError thrown";
  return {};
}
std::string replaced(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return s.replace(at, from.size(), to);
}

TEST(HjcRun, BadInputNamesFileLineAndKey) {
  struct Case {
    std::string from, to, says;
  };
  const std::vector<Case> cases = {
      {"fc = \"48 MPa\"\n", "",
       "bad.toml:5: materials.concrete.strength: missing required key 'fc'"},
      {"D1 = 0.04", "D1 = -0.04", "bad.toml:15: materials.concrete.strength.D1: must be >= 0"},
      {"K1 = \"85 GPa\"", "K1 = \"-85 GPa\"",
       "bad.toml:24: materials.concrete.eos.K1: must be > 0"},
      {"P_lock = \"0.80 GPa\"", "P_lock = \"10 MPa\"",
       "bad.toml:22: materials.concrete.eos.P_lock: must be above P_crush"},
      {"K2 = \"-171 GPa\"", "K2 = \"-300 GPa\"",
       "bad.toml:25: materials.concrete.eos.K2: with K1 and K3 the fully dense curve"},
      {"model = \"hjc\"\nP_crush", "model = \"linear\"\nP_crush",
       "bad.toml:20: materials.concrete.eos.P_crush: not used by this model"},
      {"shear_modulus = \"14.86 GPa\"", "youngs_modulus = \"34 GPa\"\npoisson_ratio = 0.15",
       "bad.toml:2: materials.concrete: missing required key 'shear_modulus'"},
      {"end_time = \"160 us\"", "end_time = \"160 us\"\ntype = \"implicit\"",
       "bad.toml:2: materials.concrete: HJC concrete needs the explicit solver"},
  };
  for (const auto& c : cases) {
    const std::string e = error_of(replaced(kCube, c.from, c.to));
    EXPECT_EQ(e.substr(0, c.says.size()), c.says) << "got: " << e;
  }
}

}  // namespace
}  // namespace mpm
