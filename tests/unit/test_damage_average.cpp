// The averaged damage of HJC's damage_length (common/mpm/solver/damage_average.hpp): what the
// lattice average must keep whatever the particles' layout: the mass-weighted sum of the
// increments (conservation, to round-off), a uniform increment uniform, the increment of a
// particle alone in its lattice cell its own, a point's increment spread no further than twice
// the length, other materials and the cap at D = 1 untouched.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "mpm/solver/damage_average.hpp"

namespace mpm {
namespace {

/// A block of particles on a jittered lattice of spacing dx, n per axis, from `origin`, mass
/// varying; the increments set by the test.
struct Cloud {
  std::vector<Vec<3>> x;
  std::vector<double> m, dD, D;
  std::vector<std::uint8_t> mat;
  Cloud(int n, double dx, Vec<3> origin, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-0.3, 0.3), mass(0.5, 1.5);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k) {
          x.push_back(origin + dx * Vec<3>(i + 0.5 + u(rng), j + 0.5 + u(rng), k + 0.5 + u(rng)));
          m.push_back(mass(rng) * 1e-6);
          dD.push_back(0.0);
          D.push_back(0.0);
          mat.push_back(1);
        }
  }
  DamageAverageInput<3> input(double length) {
    DamageAverageInput<3> in;
    in.n = x.size();
    in.x = x.data();
    in.m = m.data();
    in.material = mat.data();
    in.mat = 1;
    in.length = length;
    in.increment = dD.data();
    in.damage = D.data();
    return in;
  }
  double mass_weighted(const std::vector<double>& v) const {
    double s = 0;
    for (std::size_t i = 0; i < v.size(); ++i) s += m[i] * v[i];
    return s;
  }
};

TEST(DamageAverage, KeepsTheMassWeightedSumOfTheIncrements) {
  // A localised band of damage in a 20^3 cloud of 0.5 mm spacing straddling the origin (the
  // lattice's negative nodes too), averaged over 2 mm: sum m dD before = sum m (D_new - D_old).
  Cloud c(20, 0.5e-3, Vec<3>(-3e-3, -1e-3, -5e-3), 7);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 0.01);
  for (std::size_t i = 0; i < c.x.size(); ++i)
    if (std::abs(c.x[i][0] - 1e-3) < 0.6e-3) c.dD[i] = u(rng);
  const double before = c.mass_weighted(c.dD);
  ASSERT_GT(before, 0);
  std::vector<double> Q, M;
  EXPECT_GT(average_damage<3>(c.input(2e-3), nullptr, Q, M), 0u);
  EXPECT_NEAR(c.mass_weighted(c.D), before, 1e-12 * before);
  // It spread: more particles damaged than the band held, none beyond 2 l of it.
  int band = 0, damaged = 0;
  for (std::size_t i = 0; i < c.x.size(); ++i) {
    band += c.dD[i] > 0;
    damaged += c.D[i] > 0;
    if (c.D[i] > 0) {
      EXPECT_LT(std::abs(c.x[i][0] - 1e-3), 0.6e-3 + 4e-3 + 1e-12);
    }
  }
  EXPECT_GT(damaged, 2 * band);
}

TEST(DamageAverage, AUniformIncrementStaysUniform) {
  Cloud c(12, 0.7e-3, Vec<3>(0.1e-3, 0.2e-3, -4e-3), 11);
  for (double& d : c.dD) d = 0.003;
  std::vector<double> Q, M;
  average_damage<3>(c.input(1.5e-3), nullptr, Q, M);
  for (double D : c.D) EXPECT_NEAR(D, 0.003, 1e-15);
}

TEST(DamageAverage, AParticleAloneInItsLatticeCellKeepsItsOwnIncrement) {
  // A length far below the particles' spacing: every lattice cell holds one particle, its
  // nodes that particle's increment alone, and the average is local damage.
  Cloud c(6, 1e-3, Vec<3>(0, 0, 0), 5);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0.0, 0.02);
  for (double& d : c.dD) d = u(rng);
  std::vector<double> Q, M;
  average_damage<3>(c.input(0.05e-3), nullptr, Q, M);
  for (std::size_t i = 0; i < c.x.size(); ++i) EXPECT_NEAR(c.D[i], c.dD[i], 1e-15);
}

TEST(DamageAverage, APointSpreadsOverTwiceTheLengthAndLeavesOtherMaterialsAlone) {
  Cloud c(16, 0.5e-3, Vec<3>(0, 0, 0), 13);
  // One particle damages; a second material's particles sit among the first's.
  std::size_t src = 0;
  double best = 1;
  const Vec<3> centre(4e-3, 4e-3, 4e-3);
  for (std::size_t i = 0; i < c.x.size(); ++i)
    if ((c.x[i] - centre).norm() < best) best = (c.x[i] - centre).norm(), src = i;
  c.dD[src] = 0.5;
  for (std::size_t i = 0; i < c.x.size(); i += 7)
    if (i != src) c.mat[i] = 2, c.dD[i] = 0.9, c.D[i] = 0.25;
  std::vector<double> Q, M;
  const double l = 1e-3;
  average_damage<3>(c.input(l), nullptr, Q, M);
  double kept = 0, total = 0;
  for (std::size_t i = 0; i < c.x.size(); ++i) {
    if (c.mat[i] == 2) {
      EXPECT_EQ(c.D[i], 0.25);  // untouched, its own increment not read
      continue;
    }
    total += c.m[i] * c.D[i];
    if (c.D[i] > 0) {
      for (int a = 0; a < 3; ++a) EXPECT_LT(std::abs(c.x[i][a] - c.x[src][a]), 2 * l);
    }
    if (i == src) kept = c.D[i];
  }
  EXPECT_NEAR(total, c.m[src] * 0.5, 1e-12 * c.m[src]);
  EXPECT_LT(kept, 0.5 / 4);  // spread over its neighbours, not kept
}

TEST(DamageAverage, CapsTheDamageAtOneAndDoesNothingWithoutIncrements) {
  Cloud c(8, 0.5e-3, Vec<3>(0, 0, 0), 17);
  for (std::size_t i = 0; i < c.x.size(); ++i) c.D[i] = 0.99;
  std::vector<double> Q, M;
  EXPECT_EQ(average_damage<3>(c.input(1e-3), nullptr, Q, M), 0u);
  for (double D : c.D) EXPECT_EQ(D, 0.99);
  for (double& d : c.dD) d = 0.05;
  average_damage<3>(c.input(1e-3), nullptr, Q, M);
  for (double D : c.D) EXPECT_EQ(D, 1.0);
}

TEST(DamageAverage, WorksInTwoDimensions) {
  std::vector<Vec<2>> x;
  std::vector<double> m, dD, D;
  std::vector<std::uint8_t> mat;
  for (int i = 0; i < 30; ++i)
    for (int j = 0; j < 30; ++j) {
      x.emplace_back(0.25e-3 + 0.5e-3 * i, -7e-3 + 0.5e-3 * j);
      m.push_back(1e-6 * (1 + 0.01 * i));
      dD.push_back(i == 10 ? 0.02 : 0.0);
      D.push_back(0.0);
      mat.push_back(0);
    }
  DamageAverageInput<2> in;
  in.n = x.size(), in.x = x.data(), in.m = m.data(), in.material = mat.data(), in.mat = 0;
  in.length = 1.2e-3, in.increment = dD.data(), in.damage = D.data();
  std::vector<double> Q, M;
  average_damage<2>(in, nullptr, Q, M);
  double before = 0, after = 0;
  for (std::size_t k = 0; k < x.size(); ++k) before += m[k] * dD[k], after += m[k] * D[k];
  EXPECT_NEAR(after, before, 1e-12 * before);
  // The column of particles at i = 10 spreads across x only: D depends on i alone.
  for (std::size_t k = 0; k + 30 < x.size(); ++k)
    if (k % 30 != 29) {
      EXPECT_NEAR(D[k], D[k + 1], 1e-15);
    }
}

}  // namespace
}  // namespace mpm
