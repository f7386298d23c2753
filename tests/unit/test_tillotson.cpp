// The Tillotson equation of state (docs/eos-tillotson.md), built by its registry key, against
// pressures computed by hand in each of its regions, the continuity of its branches where they
// meet, its derivatives, and its use in the constitutive update (energy equation, sound speed);
// its scene keys.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "mpm/core/error.hpp"
#include "mpm/scene/scene.hpp"
#include "mpm/solver/materials/material.hpp"

namespace mpm {
namespace {

/// Tillotson's aluminium (Tillotson 1962, as tabulated by Melosh 1989): rho0 = 2700 kg/m^3,
/// A = 75.2 GPa, B = 65 GPa, a = 0.5, b = 1.63, E0 = 5 MJ/kg, E_iv = 3 MJ/kg, E_cv = 13.9
/// MJ/kg, alpha = beta = 5. A fluid (no strength), so the update's pressure is the EOS's.
MaterialSpec aluminium() {
  MaterialSpec m;
  m.name = "aluminium";
  m.density = 2700;
  m.youngs_modulus = 70e9;
  m.poisson_ratio = 0.33;
  m.strength.model = StrengthModel::J2;  // A = B = 0: no deviatoric stress
  m.eos.model = EosModel::Tillotson;
  m.eos.tillotson = {0.5, 1.63, 75.2e9, 65e9, 5e6, 3e6, 13.9e6, 5, 5};
  return m;
}

struct Pressure {
  double p, B, K;  ///< p = A + B e at the state, dp/de, rho dp/drho (or its floor)
};
Pressure eos_at(const Eos& eos, double rho, double e) {
  double A, B, K;
  eos.coefficients(1, &rho, &e, &A, &B, &K);
  return {A + B * e, B, K};
}

// Pressures in each region against the form of docs/eos-tillotson.md evaluated by hand (in
// 30-digit arithmetic, /tmp-free: the numbers are written here). Terms are at most a few times
// the result (the cold state's A mu + B mu^2 + thermal cancels to a third), so double
// round-off stays below 1e-14 of p; 1e-12 leaves room for the compiler's fused operations.
TEST(Tillotson, PressuresMatchHandValuesInEachRegion) {
  const MaterialSpec al = aluminium();
  const auto eos = model_registry().eos.at("tillotson")(al);
  const double rho0 = al.density;
  struct Case {
    const char* region;
    double eta, E, p;
  };
  const Case cases[] = {
      // eta = 1.2, E = 1 MJ/kg: omega = 1.13889, p = (a + b / omega) rho E + A mu + B mu^2
      {"compressed", 1.2, 1e6, 23897151219.512195},
      // eta = 0.9, E = 1 MJ/kg < E_iv: the same form in tension
      {"cold expanded", 0.9, 1e6, -2478436633.6633663},
      // eta = 0.5, E = 20 MJ/kg > E_cv: p = a rho E + (b rho E / omega + A mu e^-beta z)
      // e^-alpha z^2, z = 1
      {"hot expanded", 0.5, 20e6, 13515736318.372092},
      // eta = 0.5, E = 8 MJ/kg: (E - E_iv) / (E_cv - E_iv) = 0.4587 of p_e = 5.414 GPa, the
      // rest of p_c = -13.571 GPa
      {"partial vaporisation", 0.5, 8e6, -4862180588.7357558},
  };
  for (const Case& c : cases) {
    const Pressure s = eos_at(*eos, c.eta * rho0, c.E);
    EXPECT_NEAR(s.p, c.p, 1e-12 * std::abs(c.p)) << c.region;
  }
}

// Where the branches meet the pressure is continuous. On either side of each join, at a
// relative distance d = 1e-9, the pressures differ by the slope times the distance: below
// 1e-7 of p with the slopes here (|dp/dE| E / p and |dp/drho| rho / p under 20). The jumps
// a wrong join would leave are of the order of p itself: at eta = 0.5 the hot and cold forms
// are 2.04 against -17.38 GPa at E_iv and 9.40 against -9.44 GPa at E_cv, the blend's weights
// bridge them; at mu = 0 the hot form's A mu and B mu^2 terms vanish with mu.
TEST(Tillotson, BranchesJoinContinuously) {
  const MaterialSpec al = aluminium();
  const auto eos = model_registry().eos.at("tillotson")(al);
  const double rho0 = al.density, E_iv = 3e6, E_cv = 13.9e6, d = 1e-9;
  auto jump = [&](double rho_lo, double e_lo, double rho_hi, double e_hi) {
    const double lo = eos_at(*eos, rho_lo, e_lo).p, hi = eos_at(*eos, rho_hi, e_hi).p;
    return std::abs(hi - lo) / std::max(std::abs(lo), 1e6);
  };
  for (double eta : {0.5, 0.8, 0.95}) {
    SCOPED_TRACE("eta " + std::to_string(eta));
    EXPECT_LT(jump(eta * rho0, E_iv * (1 - d), eta * rho0, E_iv * (1 + d)), 1e-7) << "at E_iv";
    EXPECT_LT(jump(eta * rho0, E_cv * (1 - d), eta * rho0, E_cv * (1 + d)), 1e-7) << "at E_cv";
  }
  // At mu = 0, for energies in the cold, the blended and the hot range.
  for (double E : {1e6, 8e6, 20e6}) {
    EXPECT_LT(jump(rho0 * (1 - d), E, rho0 * (1 + d), E), 1e-7) << "at rho0, E " << E;
  }
}

// B = dp/de and K = rho dp/drho against central differences of the pressure, in each region
// away from the joins; the step 1e-5 relative leaves a truncation error of about 1e-10 and a
// round-off of 1e-16 / 1e-5 = 1e-11 of the terms, so 1e-6 of the derivative is safe. Where
// dp/drho falls below A / rho0 (deep cold expansion: A + 2 B mu < 0) K is the floor rho A /
// rho0, the reference bulk sound speed.
TEST(Tillotson, DerivativesAndTheSoundSpeedFloor) {
  const MaterialSpec al = aluminium();
  const auto eos = model_registry().eos.at("tillotson")(al);
  const double rho0 = al.density, A = 75.2e9;
  for (const auto& [eta, E] :
       {std::pair{1.2, 1e6}, {0.9, 1e6}, {0.5, 20e6}, {0.5, 8e6}, {0.3, 5e6}, {1.5, 20e6}}) {
    SCOPED_TRACE("eta " + std::to_string(eta) + ", E " + std::to_string(E));
    const double rho = eta * rho0, h = 1e-5;
    const Pressure s = eos_at(*eos, rho, E);
    const double dpde =
        (eos_at(*eos, rho, E * (1 + h)).p - eos_at(*eos, rho, E * (1 - h)).p) / (2 * h * E);
    const double dpdr =
        (eos_at(*eos, rho * (1 + h), E).p - eos_at(*eos, rho * (1 - h), E).p) / (2 * h * rho);
    EXPECT_NEAR(s.B, dpde, 1e-6 * std::abs(dpde));
    EXPECT_NEAR(s.K, rho * std::max(dpdr, A / rho0), 1e-6 * rho * std::abs(dpdr));
  }
  // Cold, far expanded: dp/drho = (A + 2 B mu) / rho0 + thermal < 0, so the floor.
  const double rho = 0.2 * rho0;
  const Pressure s = eos_at(*eos, rho, 0.0);
  EXPECT_LT((A + 2 * 65e9 * (0.2 - 1)) / rho0, 0.0);
  EXPECT_DOUBLE_EQ(s.K, rho * A / rho0);
  // Below zero energy (round-off only) the thermal terms are those of E = 0.
  const Pressure neg = eos_at(*eos, 0.01 * rho0, -1e3), zero = eos_at(*eos, 0.01 * rho0, 0.0);
  EXPECT_DOUBLE_EQ(neg.p, zero.p);
  EXPECT_EQ(neg.B, 0.0);
}

/// One fluid point updated through Material::update (the energy equation with the EOS).
struct Point {
  Sym sigma = Sym::Zero();
  double rho, e = 0, m = 1e-6, c = 0, eps_p = 0;
  explicit Point(double rho0) : rho(rho0) {}
  void update(const Material& mat, const Mat3& L, double dt) {
    static BlockScratch S;
    MaterialBlock b;
    b.n = 1;
    b.dt = dt;
    b.h = 1e-3;
    b.L = &L;
    b.m = &m;
    b.sigma = &sigma;
    b.rho = &rho;
    b.e = &e;
    b.eps_p = &eps_p;
    b.c = &c;
    mat.update(b, S);
  }
};

SolverSpec no_viscosity() {
  SolverSpec s;
  s.bulk_linear = s.bulk_quadratic = 0;
  return s;
}

// The update solves the energy equation e_new = e - (p_old + p_new) dv / 2 with the EOS
// nonlinear in e (two Newton steps on its tangent). Compressed by 40% and expanded hot to a
// third of rho0 in 2000 steps each, through all four regions: the energy is the trapezoidal
// work of the pressures the update returned (1e-9: the identity is exact up to round-off
// summed over the steps), and each returned pressure is the EOS's at the new state within
// 1e-6 of the pressure scale (the Newton error, (dp/de)' de^2 k / 2, is far below).
TEST(Tillotson, UpdateSolvesTheEnergyEquationOnTheEos) {
  const MaterialSpec al = aluminium();
  const Material mat(al, no_viscosity());
  const auto eos = model_registry().eos.at("tillotson")(al);
  for (const auto& [rate, e0] : {std::pair{-2.5e4, 0.0}, {5.5e4, 9e6}}) {
    Point pt(al.density);
    pt.e = e0;
    const double dt = 1e-8;
    const Mat3 L = Mat3::Identity() * (rate / 3.0);
    double work = 0, worst = 0;
    for (int k = 0; k < 2000; ++k) {
      const double p_old = -trace(pt.sigma) / 3, v_old = 1 / pt.rho;
      pt.update(mat, L, dt);
      const double p_new = -trace(pt.sigma) / 3, v_new = 1 / pt.rho;
      work += -0.5 * (p_old + p_new) * (v_new - v_old);
      worst = std::max(worst, std::abs(p_new - eos_at(*eos, pt.rho, pt.e).p));
    }
    SCOPED_TRACE("rate " + std::to_string(rate));
    EXPECT_NEAR(pt.e - e0, work, 1e-9 * std::abs(work) + 1e-6);
    EXPECT_LT(worst, 1e-6 * 75.2e9);
    EXPECT_GT(std::abs(pt.rho / al.density - 1), rate < 0 ? 0.4 : 0.6);
  }
}

// The time step's signal speed is the isentropic sound speed c^2 = dp/drho + p / rho^2 dp/de,
// measured by compressing the point by two tiny steps along its isentrope (no viscosity), in
// the compressed, partial vaporisation and hot expanded regions (1e-4: the finite difference
// over a density change of 1e-7), plus the shear term 4G / 3 rho. This material has no
// strength (J2 with A = B = 0: its deviator is returned to zero whatever the strain): expanded,
// its shear term is taken at rho0 (4G / 3 rho0, the density where a material that lost its
// strength in tension regains it; HJC's debris), compressed at its density; with a yield
// stress, 4G / 3 rho everywhere.
TEST(Tillotson, SignalSpeedIsTheIsentropicSoundSpeed) {
  MaterialSpec al = aluminium();
  const Material fluid(al, no_viscosity());
  al.strength.A = 300e6;  // a yield stress the two tiny steps stay below
  const Material solid(al, no_viscosity());
  const double G = al.shear_modulus();
  for (const Material* mat : {&fluid, &solid}) {
    const bool no_strength = mat == &fluid;
    // States where dp/drho is above the floor A / rho0 (27.9e6 m^2/s^2): 30.4e6 and 30.3e6 in
    // the two expanded ones (below it the floor makes the speed larger: the test above).
    for (const auto& [eta, E] : {std::pair{1.2, 2e6}, {0.9, 8e6}, {0.5, 60e6}}) {
      Point pt(eta * al.density);
      pt.e = E;
      const Mat3 L = Mat3::Identity() * (-1e2 / 3.0);  // tr D dt = -1e-7
      pt.update(*mat, L, 1e-9);
      const double p1 = -trace(pt.sigma) / 3, rho1 = pt.rho;
      pt.update(*mat, L, 1e-9);
      const double p2 = -trace(pt.sigma) / 3, rho2 = pt.rho;
      ASSERT_GT(p2, 0.0) << "eta " << eta;
      const double shear = 4.0 / 3.0 * G / (no_strength ? std::max(rho2, al.density) : rho2);
      const double c_s = std::sqrt((p2 - p1) / (rho2 - rho1) + shear);
      EXPECT_NEAR(pt.c, c_s, 1e-4 * c_s) << "eta " << eta << (no_strength ? ", no strength" : "");
    }
  }
}

// The scene's keys: values with units, and errors that name the key and the unit expected.
TEST(Tillotson, SceneKeysAndErrors) {
  const std::string base = R"([materials.al]
density = "2700 kg/m^3"
youngs_modulus = "70 GPa"
poisson_ratio = 0.33
[materials.al.eos]
model = "tillotson"
a = 0.5
b = 1.63
A = "75.2 GPa"
B = "65 GPa"
E0 = "5 MJ/kg"
E_iv = "3 MJ/kg"
E_cv = "13.9 MJ/kg"
alpha = 5
beta = 5
[[bodies]]
name = "plate"
material = "al"
shape = "box"
size = "1 1 1 mm"
[grid]
cell_size = "0.5 mm"
[solver]
end_time = "1 us"
)";
  const Scene s = parse_scene(base, "inline.toml", "/scenes", {});
  const TillotsonSpec& t = s.materials.at(0).eos.tillotson;
  EXPECT_EQ(s.materials.at(0).eos.model, EosModel::Tillotson);
  EXPECT_DOUBLE_EQ(t.A, 75.2e9);
  EXPECT_DOUBLE_EQ(t.E0, 5e6);
  EXPECT_DOUBLE_EQ(t.E_cv, 13.9e6);
  EXPECT_DOUBLE_EQ(t.b, 1.63);
  auto error = [&](const std::string& from, const std::string& to) {
    std::string text = base;
    text.replace(text.find(from), from.size(), to);
    try {
      parse_scene(text, "inline.toml", "/scenes", {});
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error("E0 = \"5 MJ/kg\"", "").find("missing required key 'E0' (a specific energy"),
            std::string::npos);
  EXPECT_NE(error("E0 = \"5 MJ/kg\"", "E0 = \"5 MPa\"")
                .find("inline.toml:11: materials.al.eos.E0: expected a specific energy (J/kg)"),
            std::string::npos);
  EXPECT_NE(error("E_cv = \"13.9 MJ/kg\"", "E_cv = \"2 MJ/kg\"").find("must be above E_iv"),
            std::string::npos);
  EXPECT_NE(error("alpha = 5", "alpha = 5\nc0 = \"2 km/s\"").find("c0: not used by the tillotson"),
            std::string::npos);
}

}  // namespace
}  // namespace mpm
