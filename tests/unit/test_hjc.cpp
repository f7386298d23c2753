// Holmquist-Johnson-Cook concrete with the constants of 004 Table 4 (V5, Hanchak's 48 MPa
// concrete): the three-region pressure at its boundaries and on its unloading path, the tension
// cut-off, the strength surface, its cap and its tension branch, and the damage increment,
// each against numbers computed by hand from the published formulas (docs/scene.md, HJC).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>

#include "mpm/core/error.hpp"
#include "mpm/scene/particles.hpp"
#include "mpm/solver/materials/material.hpp"
#include "mpm/solver/materials/models.hpp"

namespace mpm {
namespace {

MaterialSpec concrete() {
  MaterialSpec m;
  m.name = "concrete";
  m.density = 2440;
  HjcSpec& h = m.hjc;
  h.A = 0.79, h.B = 1.60, h.N = 0.61, h.C = 0.007, h.fc = 48e6, h.T = 4e6, h.S_max = 7.0;
  h.D1 = 0.04, h.D2 = 1.0, h.EF_min = 0.01;
  h.P_crush = 16e6, h.mu_crush = 0.001, h.P_lock = 0.80e9, h.mu_lock = 0.10;
  h.K1 = 85e9, h.K2 = -171e9, h.K3 = 208e9;
  // G = 14.86 GPa and K = P_crush / mu_crush = 16 GPa, as the scene reader sets them.
  m.youngs_modulus = 34.041361756283806e9;
  m.poisson_ratio = 0.14540248170537703;
  m.strength.model = StrengthModel::Hjc;
  m.eos.model = EosModel::Hjc;
  return m;
}

/// The HJC pressure (Pa) at mu = rho / rho0 - 1 after the largest compression mu_max, with
/// damage D, and the bulk modulus the EOS reports there.
struct PressureAt {
  double p, K;
};
PressureAt pressure(double mu, double mu_max, double D) {
  const MaterialSpec m = concrete();
  const auto eos = model_registry().eos.at("hjc")(m);
  double rho = m.density * (1 + mu), e = 0, A, B, K;
  MaterialBlock b;
  b.n = 1;
  b.rho = &rho;
  b.mu_max = &mu_max;
  b.damage = &D;
  eos->block_coefficients(b, &e, &A, &B, &K);
  EXPECT_EQ(B, 0.0);  // no energy term
  return {A, K};
}

// The relative tolerance of the pressures: they are evaluated from the same formulas as the
// hand numbers (printed to 16 digits), so only round-off separates them.
constexpr double kRel = 1e-12;

TEST(Hjc, PressureAtTheRegionBoundaries) {
  // Elastic: K_e = P_crush / mu_crush = 16 GPa; P_crush at mu_crush, half of it halfway.
  EXPECT_NEAR(pressure(0.001, 0, 0).p, 16e6, kRel * 16e6);
  EXPECT_NEAR(pressure(0.0005, 0, 0).p, 8e6, kRel * 16e6);
  EXPECT_NEAR(pressure(0.0005, 0, 0).K, 16e9 * 1.0005, kRel * 16e9);
  // Lock: the fully dense curve 85 m - 171 m^2 + 208 m^3 (GPa) reaches P_lock = 0.8 GPa at
  // m = 0.009594806918588569 (bisection by hand, to 1e-17), i.e. at mu_plock = 0.10 + 1.10 m =
  // 0.11055428761044743, where crushing ends; crushing is linear between, so halfway in mu the
  // pressure is halfway, (16 + 800) / 2 = 408 MPa.
  const double mu_plock = 0.11055428761044743;
  EXPECT_NEAR(pressure(mu_plock, 0, 0).p, 0.8e9, 1e-9 * 0.8e9);
  EXPECT_NEAR(pressure(0.5 * (0.001 + mu_plock), 0, 0).p, 408e6, 1e-9 * 0.8e9);
  // Continuous at both ends (the step across is the slope times 1e-12 of strain).
  EXPECT_NEAR(pressure(mu_plock * (1 + 1e-12), 0, 0).p, 0.8e9, 1e-3 * 1e6);
  EXPECT_NEAR(pressure(0.001 * (1 + 1e-12), 0, 0).p, 16e6, 1e-3 * 1e6);
  // Fully dense at mu = 0.2: m = 0.1 / 1.1, 85 m - 171 m^2 + 208 m^3 GPa = 6.4703230653644 GPa.
  EXPECT_NEAR(pressure(0.2, 0.2, 0).p, 6.4703230653643875e9, kRel * 6.5e9);
  // ... and reversible there: unloading from 0.25 to 0.2 follows the same curve.
  EXPECT_NEAR(pressure(0.2, 0.25, 0).p, 6.4703230653643875e9, kRel * 6.5e9);
}

TEST(Hjc, UnloadingFromACrushedState) {
  // Crushed to mu_max = 0.05: P = 16 MPa + (800 - 16) MPa (0.05 - 0.001) / (mu_plock - 0.001)
  // = 366.6572023597964 MPa; F = 0.049 / 0.10955428761 = 0.447270, unloading modulus
  // (1 - F) 16 GPa + F 85 GPa = 46.86141194238 GPa. Back at mu = 0.045: 366.657 - 46.8614 x
  // 0.005 = 132.3501426478945 MPa; reloading to 0.05 returns to the loading curve.
  EXPECT_NEAR(pressure(0.05, 0.05, 0).p, 366.6572023597964e6, kRel * 4e8);
  EXPECT_NEAR(pressure(0.045, 0.05, 0).p, 366.6572023597964e6 - 46.861411942380035e9 * 0.005,
              kRel * 4e8);
  EXPECT_NEAR(pressure(0.045, 0.05, 0).K, 46.861411942380035e9 * 1.045, kRel * 5e10);
  // A virgin particle at 0.045 is on the loading curve instead (16 + 7.15627 GPa x 0.044).
  EXPECT_NEAR(pressure(0.045, 0, 0).p, 16e6 + 7156269435.914212 * 0.044, kRel * 4e8);
}

TEST(Hjc, TensionIsCutAtTTimesOneMinusDamage) {
  // -16 MPa elastic at mu = -0.001, cut at -T = -4 MPa intact, -3 MPa at D = 0.25, 0 at D = 1.
  EXPECT_NEAR(pressure(-0.0001, 0, 0).p, -1.6e6, kRel * 1e7);
  EXPECT_NEAR(pressure(-0.001, 0, 0).p, -4e6, kRel * 1e7);
  EXPECT_NEAR(pressure(-0.001, 0, 0.25).p, -3e6, kRel * 1e7);
  EXPECT_EQ(pressure(-0.001, 0, 1.0).p, 0.0);
  // Also after crushing: from mu_max = 0.05 back to 0.04 the unloading line would give
  // 366.657 - 468.614 = -101.96 MPa; the cut holds it at -4 MPa.
  EXPECT_NEAR(pressure(0.04, 0.05, 0).p, -4e6, kRel * 1e7);
}

/// One strength update of a single particle at pressure p (Pa), damage D and mu_max, from
/// zero deviatoric stress, by a pure shear increment de_xy = 0.01 over dt; returns the block
/// scratch (flow stress in yield, plastic increment in dlambda) and the state after.
struct Sheared {
  double yield, dlambda, eps_p, D, mu_max, q;
};
/// The same for the HJC strength `st` of the material `m`, with the block's velocity gradient L
/// and tension factor (MaterialBlock::tension_factor; null: none).
Sheared shear_with(const Strength& st, const MaterialSpec& m, const Mat3* L, double* tension_factor,
                   double p, double D, double dt, double mu = 0, double mu_max = 0,
                   double g = 0.01) {
  static BlockScratch S;
  double rho = m.density * (1 + mu), eps_p = 0;
  MaterialBlock b;
  b.n = 1;
  b.dt = dt;
  b.L = L;
  b.tension_factor = tension_factor;
  b.rho = &rho;
  b.eps_p = &eps_p;
  b.damage = &D;
  b.mu_max = &mu_max;
  S.p[0] = p;
  S.s[0].setZero();
  S.de[0].setZero();
  S.de[0][5] = g;
  st.update(b, S, m.shear_modulus());
  return {S.yield[0], S.dlambda[0], eps_p, D, mu_max, std::sqrt(1.5 * ddot(S.s[0], S.s[0]))};
}
Sheared shear(double p, double D, double dt, double mu = 0, double mu_max = 0, double g = 0.01) {
  const MaterialSpec m = concrete();
  const auto st = model_registry().strength.at("hjc")(m);
  return shear_with(*st, m, nullptr, nullptr, p, D, dt, mu, mu_max, g);
}

// The equivalent strain rate of de_xy = g over dt is sqrt(2/3 x 2 g^2) / dt = 2 g / (sqrt(3) dt):
// 0.5 /s (below the reference rate 1 /s: no rate term) at dt = 0.023094010767585035 s,
// 1000 /s at dt = 1.1547005383792517e-5 s.
constexpr double kSlow = 0.023094010767585035, kFast1000 = 1.1547005383792517e-5;

TEST(Hjc, StrengthSurfaceAtKnownPoints) {
  // P* = 1, D = 0, static: (0.79 + 1.60) 48 MPa = 114.72 MPa.
  EXPECT_NEAR(shear(48e6, 0, kSlow).yield, 114.72e6, 1e-12 * 1e8);
  // P* = 2, D = 0.5, 1000 /s: (0.395 + 1.6 x 2^0.61)(1 + 0.007 ln 1000) 48 MPa
  // = (0.395 + 2.441968)(1.0483543) 48 MPa = 142.76143482674667 MPa.
  EXPECT_NEAR(shear(96e6, 0.5, kFast1000).yield, 142.76143482674667e6, 1e-9 * 1e8);
  // P* = 0 and D = 1: no strength left.
  EXPECT_EQ(shear(0, 1.0, kSlow).yield, 0.0);
  // The deviator after a plastic step lies on the surface (radial return).
  const Sheared s = shear(48e6, 0, kSlow);
  EXPECT_NEAR(s.q, 114.72e6, 1e-9 * 1e8);
}

TEST(Hjc, StrengthIsCappedAtSmax) {
  // P* = 20: 0.79 + 1.6 x 20^0.61 = 10.738 > S_max = 7, so 7 x 48 MPa = 336 MPa.
  EXPECT_NEAR(shear(960e6, 0, kSlow).yield, 336e6, 1e-12 * 336e6);
  // The cap holds with the rate term too (it multiplies before the cap).
  EXPECT_NEAR(shear(960e6, 0, kFast1000).yield, 336e6, 1e-12 * 336e6);
}

TEST(Hjc, StrengthInTensionFallsToZeroAtTheCutOff) {
  // P = -2 MPa = -T/2, D = 0: linear from A at P* = 0 to 0 at -T*: 0.79 x 0.5 x 48 MPa.
  EXPECT_NEAR(shear(-2e6, 0, kSlow).yield, 18.96e6, 1e-12 * 1e8);
  // At the damaged cut-off P = -T (1 - D) = -2 MPa for D = 0.5 nothing is left.
  EXPECT_NEAR(shear(-2e6, 0.5, kSlow).yield, 0.0, 1e-9 * 1e8);
}

TEST(Hjc, DamageIncrementFromPlasticStrain) {
  // q_tr = 2 G sqrt(3) de_xy = 514.7655 MPa (G = 14.86 GPa); at P* = 1 the flow stress is
  // 114.72 MPa, so d eps_p = (q_tr - 114.72 MPa) / (3 G) = 0.008973654105192245 and the
  // fracture strain D1 (P* + T*)^D2 = 0.04 (1 + 1/12) = 0.0433333: D = 0.20708432550443642.
  const Sheared s = shear(48e6, 0, kSlow);
  EXPECT_NEAR(s.dlambda, 0.008973654105192245, 1e-12);
  EXPECT_NEAR(s.eps_p, 0.008973654105192245, 1e-12);
  EXPECT_NEAR(s.D, 0.20708432550443642, 1e-10);
  // At P* = 0 the fracture strain D1 T* = 0.00333 is below EF_min = 0.01, which holds:
  // d eps_p = (514.7655 - 37.92) MPa / (3 G) = 0.010696652, D = 1.0696652 -> 1 (capped).
  EXPECT_EQ(shear(0, 0, kSlow).D, 1.0);
  const Sheared small = shear(0, 0, kSlow, 0, 0, 0.0015);  // q_tr = 77.214832 MPa
  EXPECT_NEAR(small.D, (2 * 14.86e9 * std::sqrt(3.0) * 0.0015 - 37.92e6) / (3 * 14.86e9) / 0.01,
              1e-12);
}

TEST(Hjc, DamageIncrementFromCrushing) {
  // Crushed from rest to mu = 0.05 with no shear: the plastic volumetric strain is where the
  // unloading line from there meets P = 0, 0.05 - 366.6572 MPa / 46.86141 GPa =
  // 0.04217571158951353; at P* = 366.6572 / 48 = 7.6386917 the fracture strain is
  // 0.04 (P* + 1/12) = 0.3088810: D = 0.1365435598855256. mu_max follows the compression.
  const Sheared s = shear(366.6572023597964e6, 0, kSlow, 0.05, 0, 0.0);
  EXPECT_EQ(s.dlambda, 0.0);
  EXPECT_NEAR(s.D, 0.1365435598855256, 1e-12);
  EXPECT_NEAR(s.mu_max, 0.05, 1e-15);  // from rho = 1.05 rho0 (round-off)
  // Unloading adds no damage and keeps mu_max.
  const Sheared u = shear(132e6, 0.1, kSlow, 0.045, 0.05, 0.0);
  EXPECT_EQ(u.D, 0.1);
  EXPECT_EQ(u.mu_max, 0.05);
}

/// One HJC point with its whole state, updated through Material::update.
struct Point {
  Sym sigma = Sym::Zero();
  double rho = 2440, e = 0, eps_p = 0, D = 0, mu_max = 0, m = 1e-6, c = 0, thickness = 1;
  void update(const Material& mat, const Mat3& L, double dt, bool plane_stress) {
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
    b.damage = &D;
    b.mu_max = &mu_max;
    b.c = &c;
    b.plane_stress = plane_stress;
    b.thickness = plane_stress ? &thickness : nullptr;
    mat.update(b, S);
  }
};

// Plane stress repeats the whole update from the state of t^n until sigma_zz = 0, so the HJC
// history (damage, mu_max) must be restored before each pass: the converged plane-stress
// update then equals the 3D update at the rate it found, L_zz = (thickness ratio - 1) / dt.
// Compressed in x (strain 0.001 a step, y held) for 30 steps, the sheet crushes, yields and
// damages; a pass that kept the history of the one before would add the damage of every pass
// (several per step). Tolerance: L_zz recovered from the thickness carries round-off of 1e-16
// / dt, which moves the stresses by ~1e-9 of their size.
TEST(Hjc, PlaneStressIterationRestoresTheHistory) {
  SolverSpec no_viscosity;
  no_viscosity.bulk_linear = no_viscosity.bulk_quadratic = 0;
  const Material mat(concrete(), no_viscosity);
  Point sheet, solid;
  const double dt = 1e-7;
  for (int step = 0; step < 30; ++step) {
    Mat3 L = Mat3::Zero();
    L(0, 0) = -0.001 / dt;
    const double t0 = sheet.thickness;
    sheet.update(mat, L, dt, true);
    L(2, 2) = (sheet.thickness / t0 - 1.0) / dt;
    solid.update(mat, L, dt, false);
    EXPECT_NEAR(sheet.D, solid.D, 1e-9) << "step " << step;
    EXPECT_NEAR(sheet.mu_max, solid.mu_max, 1e-12) << "step " << step;
    EXPECT_NEAR(sheet.sigma[0], solid.sigma[0], 1e-7 * 1e8) << "step " << step;
  }
  EXPECT_LT(std::abs(sheet.sigma[2]), 1e-6 * std::abs(sheet.sigma[0]));  // plane stress held
  EXPECT_GT(sheet.D, 0.05);                                              // it did damage
  EXPECT_GT(sheet.mu_max, 0.001);                                        // and crush
}

// Concrete fully damaged (D = 1) has no strength at zero pressure or in tension: its deviator
// is returned to zero whatever the strain, and it regains strength only when compressed back
// to rho0. The signal speed that sets the time step keeps the shear term at that density:
// sqrt(K / rho0 + 4G / 3 rho0) in expansion (HJC's p = K mu has rho dp/drho = K rho / rho0), the
// intact speed, at any density. With 4G / 3 rho, debris of V5 flung off the slab at rho0 / 3000
// set a step of 22 ns (130 km/s; the run took 6180 steps where 993 do).
TEST(Hjc, FullyDamagedExpandedConcreteKeepsTheStepOfRho0) {
  SolverSpec no_viscosity;
  no_viscosity.bulk_linear = no_viscosity.bulk_quadratic = 0;
  const MaterialSpec spec = concrete();
  const Material mat(spec, no_viscosity);
  const double K = 16e9, G = mat.shear_modulus(), rho0 = spec.density;
  const double c0 = std::sqrt((K + 4.0 / 3.0 * G) / rho0);
  Point intact;
  intact.update(mat, Mat3::Zero(), 1e-9, false);
  EXPECT_NEAR(intact.c, c0, 1e-12 * c0);
  const Mat3 expanding = Mat3::Identity() * (1e2 / 3.0);  // tr D = 100 / s
  for (const double ratio : {0.9, 1e-2, 1.0 / 3000}) {
    Point d;
    d.rho = rho0 * ratio;
    d.D = 1.0;
    d.update(mat, expanding, 1e-9, false);
    EXPECT_EQ(d.sigma.norm(), 0.0) << ratio;  // p = K mu < 0 is past the cut-off T (1 - D) = 0
    EXPECT_NEAR(d.c, c0, 1e-9 * c0) << ratio;
  }
}

// The opt-in rate-dependent tensile strength: Malvar and Ross's (1998) factor for f'c = 48 MPa,
// delta = 1 / (1 + 8 x 4.8) = 0.025380710659898477, beta = 10^(6 delta - 2) =
// 0.014199866584204338: (rate / 1e-6 /s)^delta up to 1 /s, beta (rate / 1e-6 /s)^(1/3) above;
// hand values 1.1916319307657184 at 1e-3 /s, 1.4199866584204337 at 1 /s (both branches),
// 6.590994217603407 at 100 /s, 14.199866584204333 at 1000 /s.
TEST(Hjc, TensionRateFactorIsMalvarRoss) {
  HjcSpec h = concrete().hjc;
  EXPECT_EQ(hjc_tension_dif(h, 1000.0), 1.0);  // tension_rate "none": HJC as published
  h.tension_rate = HjcSpec::TensionRate::MalvarRoss;
  EXPECT_EQ(hjc_tension_dif(h, 1e-7), 1.0);   // below the quasi-static rate: T itself
  EXPECT_EQ(hjc_tension_dif(h, -50.0), 1.0);  // no stretching (compression on every axis)
  EXPECT_NEAR(hjc_tension_dif(h, 1e-3), 1.1916319307657184, 1e-13);
  EXPECT_NEAR(hjc_tension_dif(h, 1.0), 1.4199866584204337, 1e-13);
  EXPECT_NEAR(hjc_tension_dif(h, 1.0 + 1e-9), 1.4199866588937624, 1e-13);  // continuous at 1 /s
  EXPECT_NEAR(hjc_tension_dif(h, 100.0), 6.590994217603407, 1e-12);
  EXPECT_NEAR(hjc_tension_dif(h, 1000.0), 14.199866584204333, 1e-12);
  h.tension_dif_max = 5.0;
  EXPECT_EQ(hjc_tension_dif(h, 1000.0), 5.0);
  EXPECT_NEAR(hjc_tension_dif(h, 1.0), 1.4199866584204337, 1e-13);  // below the cap: the law
}

// The largest principal value that the rate law reads, against tensors with known eigenvalues:
// diagonal ones in any order, and diag(3, 1, -2) turned by 30 degrees about z (xx = 3 cos^2 +
// sin^2 = 2.5, yy = 1.5, xy = (3 - 1) sin cos = 0.8660254037844386).
TEST(Hjc, LargestPrincipalValue) {
  Sym a;
  a << -1, 4, 2, 0, 0, 0;
  EXPECT_NEAR(largest_eigenvalue(a), 4.0, 1e-14);
  a << 0.5, 0.5, 0.5, 0, 0, 0;  // isotropic: J2 = 0
  EXPECT_EQ(largest_eigenvalue(a), 0.5);
  a << 2.5, 1.5, -2, 0, 0, 0.8660254037844386;
  EXPECT_NEAR(largest_eigenvalue(a), 3.0, 1e-14);
  a << 0, 0, 0, 0, 0, 2;  // pure shear: +-2
  EXPECT_NEAR(largest_eigenvalue(a), 2.0, 1e-14);
}

// Expanded equally on all three axes at 1000 /s for one step of 2 us (tr D dt = 0.006, so
// rho0 / rho - 1 = 0.006 and the elastic pressure K mu would be -95.4 MPa; no deviator, no
// bulk viscosity in expansion), the concrete holds the tension cut: T = 4 MPa as published,
// 14.199866584204333 T = 56.79946633681733 MPa with the rate law (the largest principal strain
// rate is 1000 /s), 5 T = 20 MPa with the factor capped at 5.
TEST(Hjc, TensionCutFollowsTheStrainRate) {
  SolverSpec solver;
  const Mat3 L = Mat3::Identity() * 1000.0;
  const auto held = [&](const MaterialSpec& spec) {
    const Material mat(spec, solver);
    Point p;
    p.update(mat, L, 2e-6, false);
    EXPECT_EQ(p.sigma[0], p.sigma[1]);
    EXPECT_EQ(p.sigma[3], 0.0);
    return p.sigma[0];  // tension positive
  };
  MaterialSpec spec = concrete();
  EXPECT_NEAR(held(spec), 4e6, 1e-6);
  spec.hjc.tension_rate = HjcSpec::TensionRate::MalvarRoss;
  EXPECT_NEAR(held(spec), 56.79946633681733e6, 1e-5);
  spec.hjc.tension_dif_max = 5.0;
  EXPECT_NEAR(held(spec), 20e6, 1e-6);
}

// The strength's tension branch and the fracture strain take the same T: at 100 /s T is
// 6.590994217603407 x 4 MPa = 26.363976870413627 MPa, so at P = -2 MPa the flow stress is
// 0.79 (1 - 2 / 26.363976870413627) 48 MPa = 35.04334749902206 MPa (18.96 MPa with the static
// T), and the fracture strain at P* = 0 is D1 T* = 0.04 x 26.364 / 48 = 0.021969980725344687
// (above EF_min = 0.01, which holds with the static T*): sheared by de_xy = 0.0015 at P = 0
// (q_tr = 77.214832 MPa over the flow stress 37.92 MPa) the damage is d eps_p / 0.02197.
TEST(Hjc, StrengthAndDamageTakeTheRateDependentT) {
  MaterialSpec m = concrete();
  m.hjc.tension_rate = HjcSpec::TensionRate::MalvarRoss;
  const auto st = model_registry().strength.at("hjc")(m);
  EXPECT_TRUE(st->rate_dependent_tension());
  EXPECT_FALSE(model_registry().strength.at("hjc")(concrete())->rate_dependent_tension());
  // rate > 0: the factor at that rate, handed in; rate < 0: the model works it out (NaN)
  // from L, stretched along x only (uniaxial strain, as in a spall plane) at -rate.
  const auto sheared = [&](double p, double g, double rate) {
    const Mat3 L = Eigen::Vector3d(-rate, 0, 0).asDiagonal();
    double factor = rate > 0 ? hjc_tension_dif(m.hjc, rate) : std::nan("");
    const Sheared s = shear_with(*st, m, &L, &factor, p, 0, kSlow, 0, 0, g);
    return std::pair{s.yield, s.D};
  };
  EXPECT_NEAR(sheared(-2e6, 1e-6, 100.0).first, 35.04334749902206e6, 1e-12 * 1e8);
  EXPECT_NEAR(sheared(-2e6, 1e-6, 1e-7).first, 18.96e6, 1e-12 * 1e8);
  EXPECT_NEAR(sheared(-2e6, 1e-6, -100.0).first, 35.04334749902206e6, 1e-12 * 1e8);
  const double G = m.shear_modulus();
  const double dl = (2 * G * std::sqrt(3.0) * 0.0015 - 37.92e6) / (3 * G);
  EXPECT_NEAR(sheared(0, 0.0015, 100.0).second, dl / 0.021969980725344687, 1e-12);
  EXPECT_NEAR(sheared(0, 0.0015, 1e-7).second, dl / 0.01, 1e-12);
  EXPECT_NEAR(sheared(0, 0.0015, -100.0).second, dl / 0.021969980725344687, 1e-12);
}

TEST(Hjc, ColumnsOnlyWhenUsed) {
  Scene s;
  s.materials.push_back(concrete());
  const ColumnNeeds hjc = column_needs(s);
  EXPECT_TRUE(hjc.damage && hjc.mu_max && hjc.eps_p);
  EXPECT_FALSE(hjc.T || hjc.failed);
  s.materials[0].strength = StrengthSpec{};
  s.materials[0].eos = EosSpec{};
  const ColumnNeeds plain = column_needs(s);
  EXPECT_FALSE(plain.damage || plain.mu_max);
}

}  // namespace
}  // namespace mpm
