#pragma once
/// Physical quantities written with units in the scene file: "7.6 mm", "190 m/s", "117 GPa",
/// "8930 kg/m^3", "30.6 us", "383 J/(kg*K)", "0 0 -190 m/s". Everything is converted to SI.
#include <array>
#include <string>
#include <string_view>
#include <vector>

namespace mpm {

/// Exponents of mass, length, time and temperature. Angles are dimensionless ("deg", "rad").
struct Dimension {
  int M = 0, L = 0, T = 0, K = 0;
  friend bool operator==(const Dimension&, const Dimension&) = default;
};

namespace dim {
inline constexpr Dimension none{0, 0, 0, 0};
inline constexpr Dimension length{0, 1, 0, 0};
inline constexpr Dimension time{0, 0, 1, 0};
inline constexpr Dimension mass{1, 0, 0, 0};
inline constexpr Dimension temperature{0, 0, 0, 1};
inline constexpr Dimension velocity{0, 1, -1, 0};
inline constexpr Dimension acceleration{0, 1, -2, 0};
inline constexpr Dimension density{1, -3, 0, 0};
inline constexpr Dimension pressure{1, -1, -2, 0};  ///< also stress, modulus
inline constexpr Dimension force{1, 1, -2, 0};
inline constexpr Dimension energy{1, 2, -2, 0};
inline constexpr Dimension rate{0, 0, -1, 0};             ///< strain rate, 1/s
inline constexpr Dimension specific_heat{0, 2, -2, -1};   ///< J/(kg*K)
inline constexpr Dimension specific_energy{0, 2, -2, 0};  ///< J/kg
}  // namespace dim

/// A number and its dimension, value in SI.
struct Quantity {
  double value = 0;
  Dimension dim;
};

/// Parses "number [unit]" ("7.6 mm", "1e3", "117GPa"). Throws std::invalid_argument with a
/// message saying what is wrong (unknown unit, no number, junk after the unit).
Quantity parse_quantity(std::string_view text);

/// Parses a unit expression alone ("kg/m^3", "J/(kg*K)", "1/s"); returns its SI factor.
Quantity parse_unit(std::string_view unit);

/// Parses "x y z [unit]" or "x, y, z unit" into n SI values (the unit applies to all).
/// Throws std::invalid_argument when the count or the unit is wrong.
std::vector<Quantity> parse_vector(std::string_view text);

/// Human name of a dimension with its SI unit, e.g. "a density (kg/m^3)".
std::string describe(const Dimension& d);

/// A length in metres as millimetres for messages, 6 significant digits, no unit: "0.0475".
std::string format_mm(double metres);

/// A number for messages, 6 significant digits ("%.6g"): "0.0475", "1e-05".
std::string format_g6(double x);

/// A count for messages: whole digits below 1e18 ("1000000000000000"), else "%.3g" ("1e+20").
std::string format_count(double n);

}  // namespace mpm
