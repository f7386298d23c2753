// APIC (solver.scheme = "APIC", Jiang et al. 2015) on quadratic B-splines (grid.shape =
// "bspline"): angular momentum kept by the transfers, and a rigid motion that stays rigid.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "mpm/core/error.hpp"
#include "mpm/grid/bspline_grid.hpp"
#include "mpm/prep/initial_fields.hpp"
#include "mpm/prep/region.hpp"
#include "mpm/prep/voxelise.hpp"
#include "mpm/solver/explicit/explicit_solver.hpp"

namespace mpm {
namespace {

// examples/spinning-disk/scene.toml: plane strain steel, 4 mm in radius on 1 mm cells (four
// cells in radius, the coarsest of the study), 50 000 rad/s about its centre.
const char* kDisk = R"toml(
[scene]
dimension = 2
[materials.steel]
density = "7850 kg/m^3"
youngs_modulus = "200 GPa"
poisson_ratio = 0.3
[[bodies]]
name = "disk"
material = "steel"
shape = "sphere"
radius = "4 mm"
angular_velocity = "50000 rad/s"
[grid]
cell_size = "1 mm"
domain = { min = "-8 -8 mm", max = "8 8 mm" }
shape = "bspline"
[solver]
scheme = "APIC"
end_time = "125.664 us"
bulk_viscosity = false
)toml";

ColumnStore model(const Scene& scene, Lattice& lattice) {
  lattice = make_lattice(scene);
  std::vector<BodyReport> report;
  ColumnStore cols = voxelise(scene, lattice, report);
  apply_initial_fields(scene, cols);
  return cols;
}

/// Angular momentum about the origin with APIC's affine part: sum m (x cross v) + m (B_yx -
/// B_xy), B = C D_p, D_p = h^2 / 4 I on quadratic B-splines (Jiang et al. 2015, eq. 13).
double angular_momentum(ColumnStore& cols, double h) {
  const auto* x = cols.get<Vec<2>>(col::x);
  const auto* v = cols.get<Vec<2>>(col::v);
  const auto* m = cols.get<double>(col::m);
  const auto* C = cols.get<Mat<2>>(col::C);
  double L = 0;
  for (std::size_t i = 0; i < cols.size(); ++i)
    L += m[i] * (x[i][0] * v[i][1] - x[i][1] * v[i][0] + 0.25 * h * h * (C[i](1, 0) - C[i](0, 1)));
  return L;
}

/// The steady state of the disk (plane strain, free rim): sigma_r = a (R^2 - r^2), sigma_theta =
/// a R^2 - b r^2, sigma_zz = nu (sigma_r + sigma_theta), a = (3 - 2 nu) / (8 (1 - nu)) rho w^2,
/// b = (1 + 2 nu) / (8 (1 - nu)) rho w^2; rho w^2 = 1.9625e13 Pa/m^2, R^2 = 16e-6 m^2.
const char* kSteady =
    "stress_field = { "
    "xx = \"(2.4/5.6)*1.9625e13*16e-6 - (1.6/5.6)*1.9625e13*(x^2+y^2) - (0.4/2.8)*1.9625e13*x^2\", "
    "yy = \"(2.4/5.6)*1.9625e13*16e-6 - (1.6/5.6)*1.9625e13*(x^2+y^2) - (0.4/2.8)*1.9625e13*y^2\", "
    "zz = \"0.3*(2*(2.4/5.6)*1.9625e13*16e-6 - (3.6/5.6)*1.9625e13*(x^2+y^2))\", "
    "xy = \"-(0.4/2.8)*1.9625e13*x*y\" }\n";

struct Turn {
  double drift = 0;  ///< largest |L / L0 - 1| over the turn
  double peak = 0;   ///< largest principal stress magnitude over the turn / sigma_c
  double px = 0;     ///< momentum along x at the end, kg m/s per m
  long steps = 0;
};

/// One full turn of the disk (kDisk, with `extra` after the spin), step by step.
Turn one_turn(const std::string& extra) {
  std::string text = kDisk;
  const std::string spin = "angular_velocity = \"50000 rad/s\"\n";
  text.insert(text.find(spin) + spin.size(), extra);
  const Scene s = parse_scene(text, "disk.toml", "", {});
  Lattice lat;
  ColumnStore cols = model(s, lat);
  ExplicitSolver<BsplineGrid<2>> solver(s, BsplineGrid<2>(lat, s.boundary), cols,
                                        ScatterStrategy::Colored);
  const double h = 1e-3, L0 = angular_momentum(cols, h);
  // The steady state's largest stress, at the centre: a R^2.
  const double sigma_c = (3 - 2 * 0.3) / (8 * (1 - 0.3)) * 7850 * 5e4 * 5e4 * 16e-6;
  Turn turn;
  while (solver.time() < s.solver.end_time) {
    solver.step(std::min(solver.stable_dt(), s.solver.end_time - solver.time()));
    ++turn.steps;
    turn.drift = std::max(turn.drift, std::abs(angular_momentum(cols, h) / L0 - 1));
    const auto* sigma = cols.get<Sym>(col::sigma);
    const auto* v = cols.get<Vec<2>>(col::v);
    const auto* m = cols.get<double>(col::m);
    turn.px = 0;
    for (std::size_t i = 0; i < cols.size(); ++i) {
      const double c = 0.5 * (sigma[i][0] + sigma[i][1]);
      const double q = std::hypot(0.5 * (sigma[i][0] - sigma[i][1]), sigma[i][5]);
      turn.peak = std::max(turn.peak, (std::abs(c) + q) / sigma_c);
      turn.px += m[i] * v[i][0];
    }
  }
  std::printf("one turn, %ld steps: max |L/L0 - 1| %.3g, peak stress %.4g sigma_c, p_x %.3g\n",
              turn.steps, turn.drift, turn.peak, turn.px);
  return turn;
}

// Set spinning unstressed: over one full turn (1522 steps) the angular momentum, affine part
// included, stays what it was to round-off (measured 1.9e-15 of it; 1e-12 allows a few ulps a
// step; MUSL on the same grid loses 18%, examples/spinning-disk/results.md), and the
// momentum stays zero to round-off of the rim's (0.41 kg/m at 200 m/s). The disk carries the
// centrifugal load (its stress passes sigma_c = a R^2 = 134.6 MPa, the steady state's largest):
// the load comes on as a step, so the elastic disk overshoots the steady state.
TEST(Apic, SpinningDiskKeepsItsAngularMomentum) {
  const Turn turn = one_turn("");
  EXPECT_GT(turn.steps, 1000);
  EXPECT_LT(turn.drift, 1e-12) << "largest relative change of the angular momentum over a turn";
  EXPECT_GT(turn.peak, 1.0) << "largest principal stress / sigma_c";
  EXPECT_LT(std::abs(turn.px), 1e-12 * 0.41 * 200);
}

// Started in its steady state (the stress field above with the spin), the disk should hold
// that stress: what the transfers add is spurious. At four cells in radius the largest
// principal stress over the turn, at any step, stays within 1.5 sigma_c (measured 1.28; the
// issue asks for twice), against 40 sigma_c with MUSL started unstressed.
TEST(Apic, SpinningDiskStartedInItsSteadyStateHoldsIt) {
  const Turn turn = one_turn(kSteady);
  EXPECT_LT(turn.drift, 1e-12);
  EXPECT_LT(turn.peak, 1.5) << "largest principal stress / sigma_c";
  EXPECT_GT(turn.peak, 0.99);
}

// A free block translating at 100 m/s with APIC on B-splines: affine fields are reproduced by
// the transfers, so every particle keeps its velocity, C stays zero and no stress appears.
TEST(Apic, TranslationStaysRigid) {
  std::string text = kDisk;
  text.replace(text.find("angular_velocity = \"50000 rad/s\""), 32, "velocity = \"100 30 m/s\"");
  const Scene s = parse_scene(text, "block.toml", "", {});
  Lattice lat;
  ColumnStore cols = model(s, lat);
  ExplicitSolver<BsplineGrid<2>> solver(s, BsplineGrid<2>(lat, s.boundary), cols,
                                        ScatterStrategy::Colored);
  for (int k = 0; k < 200; ++k) solver.step(solver.stable_dt());
  const auto* v = cols.get<Vec<2>>(col::v);
  const auto* C = cols.get<Mat<2>>(col::C);
  const auto* sigma = cols.get<Sym>(col::sigma);
  for (std::size_t i = 0; i < cols.size(); ++i) {
    EXPECT_LT((v[i] - Vec<2>(100, 30)).norm(), 1e-9);
    EXPECT_LT(C[i].norm(), 1e-6) << "1/s, against 100 m/s over 1 mm = 1e5 1/s";
    EXPECT_LT(std::abs(sigma[i][0]), 1.0) << "Pa";
  }
}

// Scenes the B-spline grid and APIC refuse name their key.
TEST(Apic, UnsupportedCombinationsNameTheirKey) {
  const auto message = [](const std::string& from, const std::string& to) {
    std::string text = kDisk;
    text.replace(text.find(from), from.size(), to);
    if (to.find("axisymmetric") != std::string::npos)  // no spin in an axisymmetric plane
      text.replace(text.find("angular_velocity = \"50000 rad/s\""), 32, "velocity = \"0 1 m/s\"");
    try {
      (void)parse_scene(text, "disk.toml", "", {});
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(
      message("dimension = 2", "dimension = 2\ngeometry = \"axisymmetric\"").find("grid.shape"),
      std::string::npos);
  EXPECT_NE(message("scheme = \"APIC\"", "type = \"implicit\"").find("solver.type"),
            std::string::npos);
}

}  // namespace
}  // namespace mpm
