// mpm-post profile's bins: a mean weighted by particle volume m / rho (the default) or by mass m
// (--weight mass), checked on two particles in one bin where the two means differ.
#include <gtest/gtest.h>

#include "mpm/core/error.hpp"
#include "mpm/post/profile.hpp"
#include "mpm/scene/particles.hpp"

namespace mpm {
namespace {

/// Two particles on the x axis at 1 and 2 mm: a dense light one and a sparse heavy one.
Frame two_particles(bool with_mass) {
  Frame f;
  f.columns.add({col::x, ScalarType::F64, 3, "m"});
  f.columns.add({col::e, ScalarType::F64, 1, "J/kg"});
  f.columns.add({col::rho, ScalarType::F64, 1, "kg/m^3"});
  if (with_mass) f.columns.add({col::m, ScalarType::F64, 1, "kg"});
  f.columns.resize(2);
  auto* x = f.columns.get<Vec3>(col::x);
  x[0] = Vec3(1e-3, 0, 0), x[1] = Vec3(2e-3, 0, 0);
  double* e = f.columns.get<double>(col::e);
  e[0] = 10, e[1] = 40;
  double* rho = f.columns.get<double>(col::rho);
  rho[0] = 8000, rho[1] = 1000;
  if (with_mass) {
    double* m = f.columns.get<double>(col::m);
    m[0] = 1, m[1] = 2;  // volumes 1/8000 and 2/1000 m^3: 1 : 16
  }
  return f;
}

TEST(Profile, BinsWeighByVolumeOrByMass) {
  ProfileOptions o;
  o.field = "e";
  o.from = Vec3(0, 0, 0);
  o.to = Vec3(3e-3, 0, 0);
  o.bins = 1;
  const Frame f = two_particles(true);
  // Volumes 1 : 16: (10 + 16 * 40) / 17; masses 1 : 2: (10 + 2 * 40) / 3 = 30.
  const Profile v = make_profile(f, 3, o);
  ASSERT_EQ(v.value.size(), 1u);
  EXPECT_NEAR(v.value[0], 650.0 / 17.0, 1e-12);
  EXPECT_NEAR(v.weight[0], 1.0 / 8000 + 2.0 / 1000, 1e-15);
  o.weight = ProfileWeight::Mass;
  const Profile m = make_profile(f, 3, o);
  EXPECT_NEAR(m.value[0], 30.0, 1e-12);
  EXPECT_NEAR(m.weight[0], 3.0, 1e-15);
  // Mass weights without masses: an error naming the option.
  EXPECT_THROW(make_profile(two_particles(false), 3, o), InputError);
}

}  // namespace
}  // namespace mpm
