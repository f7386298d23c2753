// A strong shock against the Rankine-Hugoniot jump conditions: the symmetric lead-on-lead
// impact of the hypervelocity example (V4, 6.58 km/s), in one dimension.
//
// Two lead half-spaces meet at x = 0 with velocities +u_p and -u_p (the centre-of-mass frame
// of a 6.58 km/s impact). Conservation of mass, momentum and energy across a steady shock
// with the linear U_s-u_p Hugoniot gives the shocked state exactly:
//   U_s = c0 + s u_p = 6862 m/s (relative to the unshocked material),
//   rho_H = rho0 U_s / (U_s - u_p) = 21 802 kg/m^3, p_H = rho0 U_s u_p = 256 GPa,
//   e_H = u_p^2 / 2 = 5.41 MJ/kg, and the shocked material at rest.
// The shock moves out from the interface at U_s - u_p = 3572 m/s in this frame.
//
// MPM with linear shape functions rings behind a shock this strong (the pressure of single
// particles swings by +-50% around the plateau at 2 particles per cell, measured; the seed
// method has no remedy beyond the bulk viscosity), so the test asserts what conservation fixes
// and the ringing averages out of: the mean density, specific energy and velocity of the
// shocked material, the mean pressure on the interface (the momentum the right half has
// received over t: the momentum jump condition), the shock's position, and total energy.
// Measured at 0.1 mm cells and 0.8 us (MUSL / USL), and asserted:
//   mean density        +0.2% / -1.0%                    within 3%
//   mean energy         +1.2% / -5.7%                    within 10%
//   mean |velocity|     4.9% / 3.2% of u_p               under 8%
//   interface pressure  +3.2% / +1.3%                    within 5%
//   shock position      2.2 / 0.9 cells ahead            within 3 cells
//   total energy        +1.2% / -5.0%                    MUSL within 2%; USL gains at most 1%,
//                                                        loses at most 8%
// At 0.2 and 0.05 mm the same quantities stay inside these bands at 0.8 us, except USL's
// energy: it loses 2.5%, 5% and 10% at 0.2, 0.1 and 0.05 mm (a loss per step, and the finer
// grid takes more steps), so the hypervelocity scenes use MUSL.
#include <gtest/gtest.h>

#include <cmath>

#include "fixtures.hpp"
#include "mpm/solver/explicit/explicit_solver.hpp"

namespace mpm {
namespace {

using testing::block;
using testing::lattice;
using testing::scene_with;

struct ShockedState {
  double rho = 0, e = 0, v = 0, x_shock = 0, energy_drift = 0, p_interface = 0;
  double p = 0;     ///< mean pressure of the shocked material, Pa
  double v_in = 0;  ///< its mean velocity towards the interface, m/s (signed)
};

MaterialSpec lead() {
  MaterialSpec m;
  m.name = "lead";
  m.density = 11350;
  m.youngs_modulus = 22.4e9;
  m.poisson_ratio = 0.42;
  m.strength.model = StrengthModel::J2;
  m.strength.A = 12e6;
  m.strength.B = 125e6;
  m.eos.model = EosModel::MieGruneisen;
  m.eos.c0 = 2092;
  m.eos.s = 1.45;
  m.eos.gamma0 = 2.0;
  return m;
}

/// Two half-spaces of `m` meeting at x = 0 at +-up (m/s), run to t_end on cells of h; rhoH
/// (kg/m^3) is the expected shocked density (the shock is where it is half reached).
ShockedState symmetric_impact(const MaterialSpec& m, double up, double rhoH, Scheme scheme,
                              double h, double t_end) {
  const double rho0 = m.density;
  Scene sc = scene_with(m, 2, h, 1.0);
  sc.solver.scheme = scheme;
  sc.solver.bulk_linear = 0.06;
  sc.solver.bulk_quadratic = 1.5;
  sc.boundary.face = {BoundaryType::Free, BoundaryType::Free, BoundaryType::Slip,
                      BoundaryType::Slip, BoundaryType::Slip, BoundaryType::Slip};
  // 6 mm of lead either side of x = 0, one cell high; the grid reaches 2 mm beyond.
  const int half = int(std::lround(6e-3 / h)), pad = int(std::lround(2e-3 / h));
  const Lattice lat = lattice(2, Vec3(-(half + pad) * h, 0, 0), h, {2 * (half + pad), 1, 1});
  ColumnStore cols = block<2>(lat, IVec<2>(pad, 0), IVec<2>(pad + 2 * half, 1), 2, rho0,
                              [&](const Vec<2>& x) { return Vec<2>(x[0] < 0 ? up : -up, 0); });
  UniformSolver<2> solver(sc, UniformGrid<2>(lat, sc.boundary), cols);
  const double E0 = solver.balance().total();
  while (solver.time() < t_end) solver.step(std::min(solver.stable_dt(), t_end - solver.time()));

  auto p = view<2>(cols);
  // The shock: the outermost particle on the right compressed past halfway to rho_H.
  ShockedState r;
  for (std::size_t i = 0; i < p.n; ++i)
    if (p.rho[i] > 0.5 * (rho0 + rhoH)) r.x_shock = std::max(r.x_shock, p.x[i][0]);
  // The shocked material: between the interface's start-up layer (0.3 mm) and 80% of the
  // way to the shock, on both sides.
  double mass = 0;
  for (std::size_t i = 0; i < p.n; ++i) {
    const double ax = std::abs(p.x[i][0]);
    if (ax < 0.3e-3 || ax > 0.8 * r.x_shock) continue;
    mass += p.m[i];
    r.rho += p.m[i] * p.rho[i];
    r.e += p.m[i] * p.e[i];
    r.v += p.m[i] * std::abs(p.v[i][0]);
    r.p += p.m[i] * -trace(p.sigma[i]) / 3.0;
    r.v_in += p.m[i] * (p.x[i][0] > 0 ? -p.v[i][0] : p.v[i][0]);
  }
  r.rho /= mass, r.e /= mass, r.v /= mass, r.p /= mass, r.v_in /= mass;
  // The mean pressure on the interface, from the momentum the right half has received:
  // its momentum per unit area went from -rho0 L u_p to sum m v / (h x 1).
  double P = 0, M = 0;
  for (std::size_t i = 0; i < p.n; ++i)
    if (p.x[i][0] > 0) P += p.m[i] * p.v[i][0], M += p.m[i];
  r.p_interface = (P + M * up) / (h * t_end);
  r.energy_drift = solver.balance().total() / E0 - 1;
  return r;
}

TEST(Shock, SymmetricLeadImpactMatchesRankineHugoniot) {
  const double rho0 = 11350, c0 = 2092, s = 1.45, up = 3290;
  const double Us = c0 + s * up, rhoH = rho0 * Us / (Us - up), eH = 0.5 * up * up;
  const double pH = rho0 * Us * up;
  const double h = 0.1e-3, t = 0.8e-6;
  for (Scheme scheme : {Scheme::MUSL, Scheme::USL}) {
    const ShockedState r = symmetric_impact(lead(), up, rhoH, scheme, h, t);
    const auto tag = scheme == Scheme::MUSL ? "MUSL" : "USL";
    EXPECT_NEAR(r.rho, rhoH, 0.03 * rhoH) << tag;
    EXPECT_NEAR(r.e, eH, 0.10 * eH) << tag;
    EXPECT_LT(r.v, 0.08 * up) << tag << ": the shocked material is at rest";
    EXPECT_NEAR(r.p_interface, pH, 0.05 * pH) << tag;
    EXPECT_NEAR(r.x_shock, (Us - up) * t, 3 * h) << tag;
    if (scheme == Scheme::MUSL) {
      EXPECT_NEAR(r.energy_drift, 0.0, 0.02) << tag;
    } else {
      EXPECT_LT(r.energy_drift, 0.01) << tag;
      EXPECT_GT(r.energy_drift, -0.08) << tag;
    }
    std::printf(
        "%s: rho %.0f (R-H %.0f), e %.3f MJ/kg (%.3f), |v| %.0f m/s, shock at %.3f mm "
        "(%.3f), interface pressure %.1f GPa (%.1f), energy drift %+.2f%%\n",
        tag, r.rho, rhoH, r.e / 1e6, eH / 1e6, r.v, r.x_shock * 1e3, (Us - up) * t * 1e3,
        r.p_interface / 1e9, pH / 1e9, 100 * r.energy_drift);
  }
}

// Tillotson's aluminium (docs/eos-tillotson.md) in the same symmetric impact, as the check
// of the implementation against a known data set: the shocked material's mean pressure
// against aluminium's linear fit U_s = 5.35 + 1.34 u_p km/s at the particle velocity
// measured (the velocity jump across the shock: u_p less the shocked material's mean velocity
// towards the interface), within 2% (the bound), at u_p = 0.5 and 1 km/s. The form
// itself is -0.1% and +0.9% off the fit there (tillotson_hugoniot.py aluminium); the fluid
// (no strength) makes the mean pressure the Hugoniot's, viscosity included (zero on the
// plateau on average). Measured (MUSL, 0.1 mm cells, 0.6 us): -0.46% and +1.86% (the method
// adds -0.4% and +1.0%), the shock within 1.3 cells of where the fit puts it, the total energy
// within 0.8%.
TEST(Shock, TillotsonAluminiumImpactMatchesItsHugoniot) {
  MaterialSpec al;
  al.name = "aluminium";
  al.density = 2700;
  al.youngs_modulus = 70e9;
  al.poisson_ratio = 0.33;
  al.strength.model = StrengthModel::J2;  // A = B = 0: a fluid
  al.eos.model = EosModel::Tillotson;
  al.eos.tillotson = {0.5, 1.63, 75.2e9, 65e9, 5e6, 3e6, 13.9e6, 5, 5};
  const double rho0 = 2700, c0 = 5350, s = 1.34, h = 0.1e-3, t = 0.6e-6;
  for (double up : {500.0, 1000.0}) {
    const double Us = c0 + s * up, rhoH = rho0 * Us / (Us - up);
    const ShockedState r = symmetric_impact(al, up, rhoH, Scheme::MUSL, h, t);
    const double u = up - r.v_in;  // the particle velocity jump measured
    const double p_fit = rho0 * (c0 + s * u) * u;
    EXPECT_NEAR(r.p, p_fit, 0.02 * p_fit) << "u_p " << up;
    EXPECT_NEAR(r.x_shock, (Us - up) * t, 3 * h) << "u_p " << up;
    EXPECT_NEAR(r.energy_drift, 0.0, 0.02) << "u_p " << up;
    std::printf(
        "aluminium, Tillotson: u_p %.1f m/s, pressure %.3f GPa against the fit's %.3f "
        "(%+.2f%%), rho %.0f (fit %.0f), shock at %.3f mm (%.3f), energy drift %+.2f%%\n",
        u, r.p / 1e9, p_fit / 1e9, 100 * (r.p / p_fit - 1), r.rho, rhoH, r.x_shock * 1e3,
        (Us - up) * t * 1e3, 100 * r.energy_drift);
  }
}

}  // namespace
}  // namespace mpm
