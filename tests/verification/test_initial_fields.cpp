// Bodies started from the scene's initial fields (docs/scene.md, initial fields): a velocity
// formula, a spin, a stress formula, through the scene parser and mpm-prep's library.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "mpm/core/error.hpp"
#include "mpm/prep/initial_fields.hpp"
#include "mpm/prep/region.hpp"
#include "mpm/prep/voxelise.hpp"
#include "mpm/solver/explicit/explicit_solver.hpp"

namespace mpm {
namespace {

const char* kBar = R"toml(
[scene]
dimension = 2
[materials.steel]
density = "8000 kg/m^3"
youngs_modulus = "200 GPa"
poisson_ratio = 0.0
[[bodies]]
name = "bar"
material = "steel"
shape = "box"
size = "100 10 mm"
translate = "50 0 mm"
velocity_field = ["0.5*cos(pi*(x - x_min)/(x_max - x_min))", 0]
[grid]
cell_size = "5 mm"
padding = "10 mm"
[solver]
end_time = "1 s"
bulk_viscosity = { linear = 0, quadratic = 0 }
)toml";

/// The model of a scene text, as mpm-prep makes it.
ColumnStore model(const Scene& scene, Lattice& lattice) {
  lattice = fit_lattice(scene);
  std::vector<BodyReport> report;
  ColumnStore cols = voxelise(scene, lattice, report);
  apply_initial_fields(scene, cols);
  return cols;
}

// A free elastic bar (nu = 0: the bar speed c = sqrt(E / rho) in any geometry) started in its
// first mode from a velocity formula, v = v0 cos(pi (x - x_min) / L): it vibrates with period
// 2 L / c. Kinetic minus strain energy goes as cos(4 pi t / T); its zero crossings, linearly
// interpolated, come every T / 4. Over two periods at 20 cells along the bar the period is
// 0.3% long (the coarse grid's dispersion: 2 particles a cell, cell/L = 1/20); 1% allows it.
TEST(InitialFields, FreeBarInItsFirstModeVibratesAtTwoLengthsOverTheBarSpeed) {
  const Scene s = parse_scene(kBar, "bar.toml", "", {});
  Lattice lat;
  ColumnStore cols = model(s, lat);
  const double L = 0.1, c = std::sqrt(200e9 / 8000), T = 2 * L / c;
  UniformSolver<2> solver(s, UniformGrid<2>(lat, s.boundary), cols);
  EXPECT_NEAR(solver.balance().kinetic, 0.5, 1e-3) << "8 kg/m at a mean v^2/2 of 1/16 (m/s)^2";
  std::vector<double> crossings;
  double t_prev = 0, f_prev = solver.balance().kinetic - solver.balance().internal;
  while (solver.time() < 2 * T) {
    solver.step(std::min(solver.stable_dt(), 2 * T - solver.time()));
    const double f = solver.balance().kinetic - solver.balance().internal, t = solver.time();
    if ((f < 0) != (f_prev < 0)) crossings.push_back(t_prev + (t - t_prev) * f_prev / (f_prev - f));
    t_prev = t, f_prev = f;
  }
  ASSERT_GE(crossings.size(), 7u);
  const double T_run = 4 * (crossings.back() - crossings.front()) / double(crossings.size() - 1);
  EXPECT_NEAR(T_run / T, 1.0, 0.01) << "period " << T_run << " s against 2L/c = " << T << " s";
}

// A disk given an angular velocity about its centre: v = omega x (x - c) at every particle,
// so the momentum is zero and the angular momentum is omega times the particles' polar moment,
// to round-off.
TEST(InitialFields, SpinGivesRigidRotationAboutTheCentre) {
  std::string text = kBar;
  text.replace(text.find("shape = \"box\""), std::string::npos, R"(shape = "sphere"
radius = "10 mm"
translate = "3 4 mm"
angular_velocity = "100 rad/s"
[grid]
cell_size = "2 mm"
padding = "4 mm"
[solver]
end_time = "1 s"
)");
  const Scene s = parse_scene(text, "disk.toml", "", {});
  Lattice lat;
  ColumnStore cols = model(s, lat);
  const auto* x = cols.get<Vec<2>>(col::x);
  const auto* v = cols.get<Vec<2>>(col::v);
  const auto* m = cols.get<double>(col::m);
  double px = 0, py = 0, Lz = 0, J = 0;
  for (std::size_t i = 0; i < cols.size(); ++i) {
    const Vec<2> r = x[i] - Vec<2>(3e-3, 4e-3);
    EXPECT_NEAR(v[i][0], -100 * r[1], 1e-12);
    EXPECT_NEAR(v[i][1], 100 * r[0], 1e-12);
    px += m[i] * v[i][0], py += m[i] * v[i][1];
    Lz += m[i] * (r[0] * v[i][1] - r[1] * v[i][0]);
    J += m[i] * r.squaredNorm();
  }
  EXPECT_NEAR(px, 0, 1e-15);
  EXPECT_NEAR(py, 0, 1e-15);
  EXPECT_NEAR(Lz / (100 * J), 1.0, 1e-14);
}

// A stress formula: each particle takes the formula's stress, and a density at which the
// linear EOS (p = K (rho / rho0 - 1)) gives its pressure, so the body as drawn is in that state.
TEST(InitialFields, StressFieldSetsStressAndTheDensityOfItsPressure) {
  std::string text = kBar;
  text.replace(text.find("velocity_field"), text.find("[grid]") - text.find("velocity_field"),
               "stress_field = { xx = \"-3e8*(x - x_min)/(x_max - x_min)\", xy = 1e6 }\n");
  const Scene s = parse_scene(text, "bar.toml", "", {});
  Lattice lat;
  ColumnStore cols = model(s, lat);
  const auto* x = cols.get<Vec<2>>(col::x);
  const auto* sigma = cols.get<Sym>(col::sigma);
  const auto* rho = cols.get<double>(col::rho);
  ASSERT_NE(sigma, nullptr);
  const double K = 200e9 / 3;
  for (std::size_t i = 0; i < cols.size(); ++i) {
    const double sxx = -3e8 * x[i][0] / 0.1;
    EXPECT_NEAR(sigma[i][0], sxx, 1e-6 * 3e8);
    EXPECT_EQ(sigma[i][5], 1e6);
    EXPECT_EQ(sigma[i][1], 0.0);
    EXPECT_NEAR(rho[i], 8000 * (1 + (-sxx / 3) / K), 1e-9 * 8000);
  }
}

// Mistakes in formulas name the file, the line, the key and the position.
TEST(InitialFields, BadFormulasAreReportedWithTheirPosition) {
  const auto error = [](const std::string& from, const std::string& to) {
    std::string text = kBar;
    text.replace(text.find(from), from.size(), to);
    try {
      const Scene s = parse_scene(text, "bar.toml", "", {});
      Lattice lat;
      (void)model(s, lat);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string f = "\"0.5*cos(pi*(x - x_min)/(x_max - x_min))\"";
  EXPECT_NE(error(f, "\"0.5*cos(pi*x\"")
                .find("bar.toml:14: bodies.bar.velocity_field[0]: at "
                      "position"),
            std::string::npos)
      << error(f, "\"0.5*cos(pi*x\"");
  EXPECT_NE(error(f, "\"2*w\"").find("velocity_field[0]"), std::string::npos);
  EXPECT_NE(error(f, "\"sqrt(x - x_max)\"").find("gives NaN at ("), std::string::npos)
      << error(f, "\"sqrt(x - x_max)\"");
  EXPECT_NE(error(", 0]", "]").find("expected 2 formulas"), std::string::npos);
  EXPECT_NE(error("translate", "angular_velocity = \"10 Hz\"\ntranslate").find("not Hz"),
            std::string::npos);
}

}  // namespace
}  // namespace mpm
