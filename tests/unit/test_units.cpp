// Units: parse_quantity, parse_unit, parse_vector and describe.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "mpm/core/units.hpp"

namespace mpm {
namespace {

/// Relative comparison for SI values spanning many decades.
void expect_si(double actual, double expected) {
  EXPECT_NEAR(actual, expected, 1e-12 * std::abs(expected)) << "expected " << expected;
}

/// The message of the invalid_argument thrown by `f`, or a failure when none is thrown.
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  ADD_FAILURE() << "no std::invalid_argument thrown";
  return {};
}

TEST(Units, PlainNumbersAreDimensionless) {
  const Quantity q = parse_quantity("1e3");
  EXPECT_DOUBLE_EQ(q.value, 1000.0);
  EXPECT_EQ(q.dim, dim::none);
  EXPECT_DOUBLE_EQ(parse_quantity("  -2.5 ").value, -2.5);
  EXPECT_DOUBLE_EQ(parse_quantity("+4").value, 4.0);
  EXPECT_DOUBLE_EQ(parse_quantity(".5").value, 0.5);
}

TEST(Units, Lengths) {
  expect_si(parse_quantity("7.6 mm").value, 7.6e-3);
  EXPECT_EQ(parse_quantity("7.6 mm").dim, dim::length);
  expect_si(parse_quantity("3 m").value, 3.0);
  expect_si(parse_quantity("2 km").value, 2000.0);
  expect_si(parse_quantity("5 cm").value, 0.05);
  expect_si(parse_quantity("12 um").value, 12e-6);
  expect_si(parse_quantity("12 \u00b5m").value, 12e-6);  // micro sign
  expect_si(parse_quantity("12 \u03bcm").value, 12e-6);  // Greek mu
  expect_si(parse_quantity("40 nm").value, 40e-9);
  expect_si(parse_quantity("40 pm").value, 40e-12);
}

TEST(Units, Times) {
  expect_si(parse_quantity("30.6 us").value, 3.06e-5);
  EXPECT_EQ(parse_quantity("30.6 us").dim, dim::time);
  expect_si(parse_quantity("30.6 \u00b5s").value, 3.06e-5);
  expect_si(parse_quantity("2 ms").value, 2e-3);
  expect_si(parse_quantity("7 ns").value, 7e-9);
  expect_si(parse_quantity("1.5 s").value, 1.5);
}

TEST(Units, MassesAndDensities) {
  const Quantity kg = parse_quantity("3 kg");
  expect_si(kg.value, 3.0);
  EXPECT_EQ(kg.dim, dim::mass);
  expect_si(parse_quantity("3 g").value, 3e-3);
  expect_si(parse_quantity("3 mg").value, 3e-6);

  const Quantity rho = parse_quantity("8930 kg/m^3");
  expect_si(rho.value, 8930.0);
  EXPECT_EQ(rho.dim, dim::density);
  const Quantity rho_cgs = parse_quantity("8.93 g/cm^3");
  expect_si(rho_cgs.value, 8930.0);
  EXPECT_EQ(rho_cgs.dim, dim::density);
  expect_si(parse_quantity("8930 kg m^-3").value, 8930.0);
  EXPECT_EQ(parse_quantity("8930 kg*m^-3").dim, dim::density);
}

TEST(Units, PressuresForcesEnergies) {
  const Quantity e = parse_quantity("117 GPa");
  expect_si(e.value, 1.17e11);
  EXPECT_EQ(e.dim, dim::pressure);
  expect_si(parse_quantity("117GPa").value, 1.17e11);  // no space
  expect_si(parse_quantity("-1500 MPa").value, -1.5e9);
  expect_si(parse_quantity("100 kPa").value, 1e5);
  expect_si(parse_quantity("1 Pa").value, 1.0);
  EXPECT_EQ(parse_quantity("1 N/m^2").dim, dim::pressure);
  expect_si(parse_quantity("2 kN").value, 2000.0);
  EXPECT_EQ(parse_quantity("2 kN").dim, dim::force);
  EXPECT_EQ(parse_quantity("1 kg*m/s^2").dim, dim::force);
  expect_si(parse_quantity("4 kJ").value, 4000.0);
  EXPECT_EQ(parse_quantity("4 kJ").dim, dim::energy);
  EXPECT_EQ(parse_quantity("1 N m").dim, dim::energy);  // a space multiplies
  const Quantity w = parse_quantity("5 W");
  EXPECT_EQ(w.dim, (Dimension{1, 2, -3, 0}));
}

TEST(Units, VelocitiesRatesTemperatures) {
  const Quantity v = parse_quantity("190 m/s");
  expect_si(v.value, 190.0);
  EXPECT_EQ(v.dim, dim::velocity);
  expect_si(parse_quantity("1 km/s").value, 1000.0);
  expect_si(parse_quantity("1 mm/us").value, 1000.0);
  const Quantity g = parse_quantity("9.81 m/s^2");
  EXPECT_EQ(g.dim, dim::acceleration);
  EXPECT_EQ(parse_quantity("9.81 m/s/s").dim, dim::acceleration);  // '/' divides the next only
  const Quantity rate = parse_quantity("1 1/s");
  expect_si(rate.value, 1.0);
  EXPECT_EQ(rate.dim, dim::rate);
  expect_si(parse_quantity("1000 1/ms").value, 1e6);
  EXPECT_EQ(parse_quantity("1 s^-1").dim, dim::rate);
  expect_si(parse_quantity("50 Hz").value, 50.0);
  EXPECT_EQ(parse_quantity("50 Hz").dim, dim::rate);
  const Quantity t = parse_quantity("1356 K");
  expect_si(t.value, 1356.0);
  EXPECT_EQ(t.dim, dim::temperature);
}

TEST(Units, SpecificHeatWithParentheses) {
  const Quantity c = parse_quantity("383 J/(kg*K)");
  expect_si(c.value, 383.0);
  EXPECT_EQ(c.dim, dim::specific_heat);
  EXPECT_EQ(parse_quantity("383 J/(kg K)").dim, dim::specific_heat);
  EXPECT_EQ(parse_quantity("383 J / ( kg * K )").dim, dim::specific_heat);
  // Without parentheses '/' divides by kg only: J K / kg is not a specific heat.
  EXPECT_EQ(parse_quantity("383 J/kg*K").dim, (Dimension{0, 2, -2, 1}));
  EXPECT_EQ(parse_quantity("383 J/kg/K").dim, dim::specific_heat);
  expect_si(parse_quantity("0.383 J/(g*K)").value, 383.0);
}

TEST(Units, Exponents) {
  EXPECT_EQ(parse_quantity("1 m^3").dim, (Dimension{0, 3, 0, 0}));
  EXPECT_EQ(parse_quantity("1 m^-3").dim, (Dimension{0, -3, 0, 0}));
  EXPECT_EQ(parse_quantity("1 m^+2").dim, (Dimension{0, 2, 0, 0}));
  expect_si(parse_quantity("1 cm^3").value, 1e-6);  // the prefix is raised too
  expect_si(parse_quantity("1 mm^2").value, 1e-6);
  expect_si(parse_quantity("2 (mm/us)^2").value, 2e6);
  EXPECT_EQ(parse_quantity("2 (mm/us)^2").dim, (Dimension{0, 2, -2, 0}));
}

TEST(Units, Angles) {
  const Quantity d = parse_quantity("90 deg");
  expect_si(d.value, std::numbers::pi / 2);
  EXPECT_EQ(d.dim, dim::none);
  expect_si(parse_quantity("0.5 rad").value, 0.5);
}

TEST(Units, ExactNameWinsOverPrefix) {
  // "m" is the metre, never milli-nothing; "Pa" is the pascal, never peta-annum.
  EXPECT_EQ(parse_unit("m").dim, dim::length);
  EXPECT_DOUBLE_EQ(parse_unit("m").value, 1.0);
  EXPECT_EQ(parse_unit("Pa").dim, dim::pressure);
  EXPECT_DOUBLE_EQ(parse_unit("Pa").value, 1.0);
  EXPECT_DOUBLE_EQ(parse_unit("mm").value, 1e-3);
  EXPECT_DOUBLE_EQ(parse_unit("ms").value, 1e-3);
  EXPECT_EQ(parse_unit("ms").dim, dim::time);
  EXPECT_DOUBLE_EQ(parse_unit("mPa").value, 1e-3);
}

TEST(Units, ParseUnitAlone) {
  const Quantity u = parse_unit("kg/m^3");
  EXPECT_DOUBLE_EQ(u.value, 1.0);
  EXPECT_EQ(u.dim, dim::density);
  const Quantity r = parse_unit("1/s");
  EXPECT_EQ(r.dim, dim::rate);
  const Quantity g = parse_unit("g/cm^3");
  expect_si(g.value, 1000.0);
}

TEST(Units, Vectors) {
  const auto v = parse_vector("0 0 -190 m/s");
  ASSERT_EQ(v.size(), 3u);
  expect_si(v[2].value, -190.0);
  EXPECT_DOUBLE_EQ(v[0].value, 0.0);
  for (const auto& q : v) EXPECT_EQ(q.dim, dim::velocity);

  const auto c = parse_vector("1, 2, 3 mm");
  ASSERT_EQ(c.size(), 3u);
  expect_si(c[0].value, 1e-3);
  expect_si(c[1].value, 2e-3);
  expect_si(c[2].value, 3e-3);
  EXPECT_EQ(c[1].dim, dim::length);

  const auto plain = parse_vector("1 1 2");
  ASSERT_EQ(plain.size(), 3u);
  EXPECT_DOUBLE_EQ(plain[2].value, 2.0);
  EXPECT_EQ(plain[2].dim, dim::none);

  const auto two = parse_vector("10 5mm");
  ASSERT_EQ(two.size(), 2u);
  expect_si(two[1].value, 5e-3);

  const auto g = parse_vector("0,0,-9.81 m/s^2");
  ASSERT_EQ(g.size(), 3u);
  EXPECT_EQ(g[2].dim, dim::acceleration);

  const auto one = parse_vector("30 deg");
  ASSERT_EQ(one.size(), 1u);
  expect_si(one[0].value, std::numbers::pi / 6);

  // The unit "1/s" keeps its 1.
  const auto rates = parse_vector("2 3 1/s");
  ASSERT_EQ(rates.size(), 2u);
  EXPECT_EQ(rates[1].dim, dim::rate);
  EXPECT_DOUBLE_EQ(rates[1].value, 3.0);
}

TEST(Units, Describe) {
  EXPECT_EQ(describe(dim::density), "a density (kg/m^3)");
  EXPECT_EQ(describe(dim::velocity), "a velocity (m/s)");
  EXPECT_EQ(describe(dim::pressure), "a pressure (Pa)");
  EXPECT_EQ(describe(dim::length), "a length (m)");
  EXPECT_EQ(describe(dim::time), "a time (s)");
  EXPECT_EQ(describe(dim::mass), "a mass (kg)");
  EXPECT_EQ(describe(dim::temperature), "a temperature (K)");
  EXPECT_EQ(describe(dim::acceleration), "an acceleration (m/s^2)");
  EXPECT_EQ(describe(dim::force), "a force (N)");
  EXPECT_EQ(describe(dim::energy), "an energy (J)");
  EXPECT_EQ(describe(dim::rate), "a rate (1/s)");
  EXPECT_EQ(describe(dim::specific_heat), "a specific heat (J/(kg*K))");
  EXPECT_EQ(describe(dim::none), "a dimensionless number");
  EXPECT_EQ(describe(Dimension{1, -1, -3, 0}), "a quantity in kg m^-1 s^-3");
  EXPECT_EQ(describe(Dimension{0, 2, 0, 0}), "a quantity in m^2");
}

TEST(Units, UnknownUnitNamesTheUnitAndTheText) {
  const std::string m = error_of([] { parse_quantity("7.6 mmm"); });
  EXPECT_NE(m.find("unknown unit 'mmm'"), std::string::npos) << m;
  EXPECT_NE(m.find("in '7.6 mmm'"), std::string::npos) << m;
  for (const char* bad : {"1 min", "2 h", "5 %", "1 kK", "1 Gfoo", "3 inch"}) {
    const std::string e = error_of([&] { parse_quantity(bad); });
    EXPECT_NE(e.find("unknown unit"), std::string::npos) << bad << ": " << e;
  }
  const std::string p = error_of([] { parse_quantity("5 %"); });
  EXPECT_EQ(p.rfind("unknown unit '%' in '5 %' (known units: m, g, s, K, N, Pa, J, W, Hz, deg, "
                    "rad; prefixes",
                    0),
            0u)
      << p;
}

TEST(Units, MalformedQuantities) {
  struct Case {
    const char* text;
    const char* says;
  };
  const Case cases[] = {
      {"", "empty"},
      {"   ", "empty"},
      {"mm", "expected a number"},
      {"abc 5", "expected a number"},
      {"nan", "expected a number"},
      {"inf m", "expected a number"},
      {"1e999 m", "out of range"},
      {"5 m^", "exponent"},
      {"5 m^x", "exponent"},
      {"5 m^1.5", "exponent must be an integer"},
      {"5 m2", "m^2"},
      {"5 kg/", "after '/'"},
      {"5 kg*", "after '*'"},
      {"5 J/(kg*K", "missing ')'"},
      {"5 J/kg)", "unbalanced ')'"},
      {"5 ()", "empty parentheses"},
      {"5 2/s", "several"},
      {"5 (2/s)", "unexpected number '2'"},
      {"1 2 mm", "several"},
      {"1, 2 mm", "list"},
      {"5 m # comment", "unknown unit '#'"},
      {"5 -m", "unknown unit '-m'"},
      {"5 m/%", "unknown unit '%'"},
  };
  for (const auto& c : cases) {
    const std::string e = error_of([&] { parse_quantity(c.text); });
    EXPECT_NE(e.find(c.says), std::string::npos)
        << "'" << c.text << "' gave: " << e << " (wanted '" << c.says << "')";
    if (*c.text && std::string(c.text) != "   ") {
      EXPECT_NE(e.find(c.text), std::string::npos) << "message should quote the text: " << e;
    }
  }
  EXPECT_THROW(parse_unit(""), std::invalid_argument);
  EXPECT_THROW(parse_unit("furlong"), std::invalid_argument);
}

TEST(Units, MalformedVectors) {
  struct Case {
    const char* text;
    const char* says;
  };
  const Case cases[] = {
      {"", "empty"},
      {"mm", "expected numbers"},
      {"1, 2,", "after ','"},
      {"1, 2, mm", "after ','"},
      {"1 2 3 mmm", "unknown unit 'mmm'"},
      {"1 2 x 3", "unknown unit 'x'"},
      {"1 2 3 m/", "after '/'"},
  };
  for (const auto& c : cases) {
    const std::string e = error_of([&] { parse_vector(c.text); });
    EXPECT_NE(e.find(c.says), std::string::npos)
        << "'" << c.text << "' gave: " << e << " (wanted '" << c.says << "')";
  }
}

}  // namespace
}  // namespace mpm
