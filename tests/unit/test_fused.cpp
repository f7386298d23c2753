// The fused update (fused.cpp) against the composed one (strength, EOS and energy equation as
// objects, stage by stage) on full blocks of particles in random states: the same arithmetic,
// so the same results to round-off. The composed update is the one the material tests check
// against hand-computed stresses; this carries that to the fused form over elastic and plastic
// steps, compression and expansion, with the bulk viscosity on.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "mpm/solver/materials/material.hpp"

namespace mpm {
namespace {

MaterialSpec steel(StrengthModel strength, EosModel eos) {
  MaterialSpec m;
  m.name = "steel";
  m.density = 7850;
  m.youngs_modulus = 200e9;
  m.poisson_ratio = 0.29;
  m.strength.model = strength;
  m.strength.A = 350e6;
  m.strength.B = 275e6;
  m.strength.n = 1.0;
  m.strength.tangent_modulus = 2e9;
  m.eos.model = eos;
  m.eos.c0 = 4570;
  m.eos.s = 1.49;
  m.eos.gamma0 = 1.93;
  return m;
}

/// A block of kBlock particles: random velocity gradients up to `rate` (1/s) over dt, random
/// stresses up to 1.5 times the yield stress, densities within 5% of rho0, energies, strains.
struct Block {
  std::vector<Mat3> L;
  std::vector<Sym> sigma;
  std::vector<double> m, rho, e, eps_p, c;
  Block(double rho0, double rate, unsigned seed)
      : L(kBlock),
        sigma(kBlock),
        m(kBlock, 1e-6),
        rho(kBlock),
        e(kBlock),
        eps_p(kBlock),
        c(kBlock) {
    std::mt19937_64 gen(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int i = 0; i < kBlock; ++i) {
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) L[i](r, k) = rate * u(gen);
      for (int a = 0; a < 6; ++a) sigma[i][a] = 0.5e9 * u(gen);
      rho[i] = rho0 * (1.0 + 0.05 * u(gen));
      e[i] = 1e5 * (1.0 + u(gen));
      eps_p[i] = 0.2 * (1.0 + u(gen));
    }
  }
  MaterialBlock view(double dt) {
    MaterialBlock b;
    b.n = kBlock;
    b.dt = dt;
    b.h = 1e-3;
    b.L = L.data();
    b.m = m.data();
    b.sigma = sigma.data();
    b.rho = rho.data();
    b.e = e.data();
    b.eps_p = eps_p.data();
    b.c = c.data();
    return b;
  }
};

/// |a - b| within `tol` of the larger magnitude plus `floor`.
::testing::AssertionResult near(double a, double b, double tol, double floor, const char* what,
                                int i) {
  if (std::abs(a - b) <= tol * (std::max(std::abs(a), std::abs(b)) + floor))
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << what << " of particle " << i << ": fused " << a << ", composed " << b;
}

void expect_same_as_composed(const MaterialSpec& spec, double rate) {
  SolverSpec solver;
  solver.bulk_linear = 0.06;
  solver.bulk_quadratic = 1.5;
  const Material mat(spec, solver);
  ASSERT_TRUE(mat.fused()) << spec.name;
  static BlockScratch S;
  const double dt = 1e-8;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    Block fused(spec.density, rate, seed), composed(spec.density, rate, seed);
    MaterialBlock bf = fused.view(dt), bc = composed.view(dt);
    mat.update(bf, S);
    mat.update_composed(bc, S);
    ASSERT_EQ(bf.fault_index, -1);
    ASSERT_EQ(bc.fault_index, -1);
    // Round-off: some 200 operations a particle, contracted into fused multiply-adds in
    // different places by the vectorised and the scalar loop: 1e-12 of the values' scale
    // (stress: the yield stress; energy: 1e5 J/kg) leaves three orders of magnitude.
    for (int i = 0; i < kBlock; ++i) {
      for (int a = 0; a < 6; ++a)
        EXPECT_TRUE(near(fused.sigma[i][a], composed.sigma[i][a], 1e-12, 1e8, "stress", i));
      EXPECT_TRUE(near(fused.rho[i], composed.rho[i], 1e-14, 0, "density", i));
      EXPECT_TRUE(near(fused.e[i], composed.e[i], 1e-12, 1e5, "energy", i));
      EXPECT_TRUE(near(fused.eps_p[i], composed.eps_p[i], 1e-12, 1e-6, "plastic strain", i));
      EXPECT_TRUE(near(fused.c[i], composed.c[i], 1e-12, 0, "signal speed", i));
    }
  }
}

TEST(Fused, ElasticWithLinearEosMatchesTheComposedUpdate) {
  expect_same_as_composed(steel(StrengthModel::Elastic, EosModel::Linear), 1e5);
}

TEST(Fused, ElasticWithMieGrueneisenMatchesTheComposedUpdate) {
  expect_same_as_composed(steel(StrengthModel::Elastic, EosModel::MieGruneisen), 1e5);
}

TEST(Fused, J2WithMieGrueneisenMatchesTheComposedUpdateElasticAndPlastic) {
  // 1e4 / s over 10 ns: strain increments of 1e-4, most particles elastic; 1e6 / s: 1e-2,
  // most plastic (and the trial stresses above already exceed the yield stress in places).
  expect_same_as_composed(steel(StrengthModel::J2, EosModel::MieGruneisen), 1e4);
  expect_same_as_composed(steel(StrengthModel::J2, EosModel::MieGruneisen), 1e6);
}

TEST(Fused, JohnsonCookWithoutRateOrThermalTermAndBilinearMatchTheComposedUpdate) {
  expect_same_as_composed(steel(StrengthModel::JohnsonCook, EosModel::Linear), 1e6);
  MaterialSpec energy_free = steel(StrengthModel::Bilinear, EosModel::MieGruneisen);
  energy_free.eos.energy_in_expansion = false;
  expect_same_as_composed(energy_free, 1e6);
}

TEST(Fused, CompositionsWithMoreThanTheFusedFormTakeTheComposedUpdate) {
  const SolverSpec solver;
  MaterialSpec rate = steel(StrengthModel::JohnsonCook, EosModel::MieGruneisen);
  rate.strength.C = 0.014;
  EXPECT_FALSE(Material(rate, solver).fused());
  MaterialSpec power = steel(StrengthModel::J2, EosModel::Linear);
  power.strength.n = 0.5;
  EXPECT_FALSE(Material(power, solver).fused());
  MaterialSpec failing = steel(StrengthModel::J2, EosModel::MieGruneisen);
  failing.failure.plastic_strain = 0.3;
  EXPECT_FALSE(Material(failing, solver).fused());
  EXPECT_TRUE(Material(steel(StrengthModel::J2, EosModel::MieGruneisen), solver).fused());
}

}  // namespace
}  // namespace mpm
