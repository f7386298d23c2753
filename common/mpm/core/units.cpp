#include "mpm/core/units.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>

namespace mpm {
namespace {

/// A unit symbol: its SI factor, its dimension and whether SI prefixes may be put in front.
struct UnitDef {
  std::string_view symbol;
  double factor;
  Dimension dim;
  bool prefixable;
};

// Exact names are tried first, so "m" is the metre and "Pa" the pascal, never a prefix.
constexpr UnitDef kUnits[] = {
    {"m", 1.0, dim::length, true},  {"g", 1e-3, dim::mass, true},
    {"s", 1.0, dim::time, true},    {"K", 1.0, dim::temperature, false},
    {"N", 1.0, dim::force, true},   {"Pa", 1.0, dim::pressure, true},
    {"J", 1.0, dim::energy, true},  {"W", 1.0, Dimension{1, 2, -3, 0}, false},
    {"Hz", 1.0, dim::rate, false},  {"deg", std::numbers::pi / 180.0, dim::none, false},
    {"rad", 1.0, dim::none, false},
};

struct PrefixDef {
  std::string_view symbol;
  double factor;
};

constexpr PrefixDef kPrefixes[] = {
    {"G", 1e9},
    {"M", 1e6},
    {"k", 1e3},
    {"c", 1e-2},
    {"m", 1e-3},
    {"u", 1e-6},
    {"\u00b5", 1e-6} /* micro sign */,
    {"\u03bc", 1e-6} /* Greek mu */,
    {"n", 1e-9},
    {"p", 1e-12},
};

constexpr std::string_view kKnownUnits =
    "known units: m, g, s, K, N, Pa, J, W, Hz, deg, rad; prefixes G M k c m u \u00b5 n p on m, "
    "s, g, N, Pa, J";

Quantity operator*(const Quantity& a, const Quantity& b) {
  return {a.value * b.value,
          {a.dim.M + b.dim.M, a.dim.L + b.dim.L, a.dim.T + b.dim.T, a.dim.K + b.dim.K}};
}

Quantity power(const Quantity& a, int e) {
  return {std::pow(a.value, e), {a.dim.M * e, a.dim.L * e, a.dim.T * e, a.dim.K * e}};
}

bool is_space(char c) {
  return c == ' ' || c == '\t';
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
  return s;
}

/// Parses a number at the start of `s` (an optional sign, then digits or '.'). Returns the
/// number of characters used, 0 when `s` does not start with a number.
std::size_t read_number(std::string_view s, double& out) {
  std::size_t i = 0;
  bool negative = false;
  if (i < s.size() && (s[i] == '+' || s[i] == '-')) {
    negative = s[i] == '-';
    ++i;
  }
  // Only digits or '.' may start the magnitude: keeps "nan", "inf" and units out.
  if (i >= s.size() || !((s[i] >= '0' && s[i] <= '9') || s[i] == '.')) return 0;
  double v = 0;
  auto [ptr, ec] = std::from_chars(s.data() + i, s.data() + s.size(), v);
  if (ec == std::errc::result_out_of_range) {
    throw std::invalid_argument("number out of range in '" + std::string(s) + "'");
  }
  if (ec != std::errc()) return 0;
  out = negative ? -v : v;
  return static_cast<std::size_t>(ptr - s.data());
}

/// Looks up one unit symbol: exact name first, then prefix + prefixable unit.
bool lookup_symbol(std::string_view sym, Quantity& out) {
  for (const auto& u : kUnits) {
    if (u.symbol == sym) {
      out = {u.factor, u.dim};
      return true;
    }
  }
  for (const auto& p : kPrefixes) {
    if (sym.size() <= p.symbol.size() || sym.substr(0, p.symbol.size()) != p.symbol) continue;
    const std::string_view rest = sym.substr(p.symbol.size());
    for (const auto& u : kUnits) {
      if (u.prefixable && u.symbol == rest) {
        out = {p.factor * u.factor, u.dim};
        return true;
      }
    }
  }
  return false;
}

/// Recursive-descent parser of a unit expression:
///   expr   := factor { ('*' | '/' | space) factor }   ('/' divides by the next factor only)
///   factor := ( symbol | '1' | '(' expr ')' ) [ '^' int ]
class UnitParser {
 public:
  UnitParser(std::string_view unit, std::string_view context) : s_(unit), context_(context) {}

  Quantity parse() {
    skip_space();
    if (pos_ >= s_.size()) fail("empty unit");
    Quantity q = expr();
    skip_space();
    if (pos_ < s_.size()) {
      if (s_[pos_] == ')') fail("unbalanced ')'");
      fail("unexpected '" + std::string(s_.substr(pos_)) + "'");
    }
    return q;
  }

 private:
  [[noreturn]] void fail(const std::string& what, const std::string& hint = "") const {
    throw std::invalid_argument(what + " in '" + std::string(context_) + "'" +
                                (hint.empty() ? "" : " (" + hint + ")"));
  }

  void skip_space() {
    while (pos_ < s_.size() && is_space(s_[pos_])) ++pos_;
  }

  static bool is_symbol_char(std::string_view s, std::size_t i) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c >= 0x80;  // UTF-8 (µ, μ)
  }

  bool starts_factor() const {
    if (pos_ >= s_.size()) return false;
    const char c = s_[pos_];
    return c == '(' || (c >= '0' && c <= '9') || is_symbol_char(s_, pos_);
  }

  Quantity expr() {
    Quantity q = factor();
    for (;;) {
      skip_space();
      if (pos_ >= s_.size() || s_[pos_] == ')') return q;
      const char c = s_[pos_];
      if (c == '*' || c == '/') {
        ++pos_;
        skip_space();
        if (pos_ >= s_.size() || s_[pos_] == ')' || s_[pos_] == '*' || s_[pos_] == '/') {
          fail(std::string("expected a unit after '") + c + "'");
        }
        const Quantity f = factor();
        q = q * (c == '/' ? power(f, -1) : f);
      } else {
        q = q * factor();  // "N m": a space multiplies
      }
    }
  }

  Quantity factor() {
    if (!starts_factor()) {
      if (std::string_view("*/^)").find(s_[pos_]) != std::string_view::npos) {
        fail("unexpected '" + std::string(s_.substr(pos_)) + "'");
      }
      const std::size_t end = s_.find_first_of(" \t*/^()", pos_);
      fail("unknown unit '" + std::string(s_.substr(pos_, end - pos_)) + "'",
           std::string(kKnownUnits));
    }
    Quantity q;
    const char c = s_[pos_];
    if (c == '(') {
      ++pos_;
      skip_space();
      if (pos_ >= s_.size() || s_[pos_] == ')') fail("empty parentheses");
      q = expr();
      skip_space();
      if (pos_ >= s_.size() || s_[pos_] != ')') fail("missing ')'");
      ++pos_;
    } else if (c >= '0' && c <= '9') {
      const std::size_t start = pos_;
      while (pos_ < s_.size() && ((s_[pos_] >= '0' && s_[pos_] <= '9') || s_[pos_] == '.')) ++pos_;
      const std::string_view num = s_.substr(start, pos_ - start);
      if (num != "1") {
        fail("unexpected number '" + std::string(num) +
             "' in the unit (only '1' may stand alone, as in '1/s'; write powers as m^2)");
      }
      q = {1.0, dim::none};
    } else {
      const std::size_t start = pos_;
      while (pos_ < s_.size() && is_symbol_char(s_, pos_)) ++pos_;
      const std::string_view sym = s_.substr(start, pos_ - start);
      if (!lookup_symbol(sym, q)) {
        fail("unknown unit '" + std::string(sym) + "'", std::string(kKnownUnits));
      }
      if (pos_ < s_.size() && s_[pos_] >= '0' && s_[pos_] <= '9') {
        fail("unexpected '" + std::string(sym) + s_[pos_] + "' (write powers as " +
             std::string(sym) + "^" + s_[pos_] + ")");
      }
    }
    if (pos_ < s_.size() && s_[pos_] == '^') {
      ++pos_;
      std::size_t start = pos_;
      if (pos_ < s_.size() && (s_[pos_] == '-' || s_[pos_] == '+')) ++pos_;
      const std::size_t digits = pos_;
      while (pos_ < s_.size() && s_[pos_] >= '0' && s_[pos_] <= '9') ++pos_;
      if (pos_ == digits) fail("expected an integer exponent after '^'");
      if (pos_ < s_.size() && s_[pos_] == '.') fail("the exponent must be an integer");
      if (s_[start] == '+') ++start;
      int e = 0;
      auto [ptr, ec] = std::from_chars(s_.data() + start, s_.data() + pos_, e);
      if (ec != std::errc() || ptr != s_.data() + pos_ || e > 99 || e < -99) {
        fail("exponent out of range");
      }
      q = power(q, e);
    }
    return q;
  }

  std::string_view s_;
  std::string_view context_;
  std::size_t pos_ = 0;
};

Quantity parse_unit_in(std::string_view unit, std::string_view context) {
  return UnitParser(unit, context).parse();
}

}  // namespace

Quantity parse_unit(std::string_view unit) {
  return parse_unit_in(trim(unit), unit);
}

Quantity parse_quantity(std::string_view text) {
  const std::string_view t = trim(text);
  if (t.empty()) throw std::invalid_argument("empty quantity (expected a number and a unit)");
  double v = 0;
  const std::size_t n = read_number(t, v);
  if (n == 0) {
    throw std::invalid_argument("expected a number at the start of '" + std::string(text) + "'");
  }
  if (!std::isfinite(v)) {
    throw std::invalid_argument("number out of range in '" + std::string(text) + "'");
  }
  const std::string_view unit = trim(t.substr(n));
  if (unit.empty()) return {v, dim::none};
  if (unit.front() == ',') {
    throw std::invalid_argument("expected one number, found a list in '" + std::string(text) + "'");
  }
  double second = 0;
  if (read_number(unit, second) > 0 && !(unit[0] == '1' && trim(unit.substr(1)).starts_with('/'))) {
    throw std::invalid_argument("expected one number, found several in '" + std::string(text) +
                                "'");
  }
  const Quantity u = parse_unit_in(unit, text);
  return {v * u.value, u.dim};
}

std::vector<Quantity> parse_vector(std::string_view text) {
  const std::string_view t = trim(text);
  if (t.empty()) throw std::invalid_argument("empty vector (expected numbers and a unit)");
  std::vector<double> numbers;
  std::vector<std::string_view> tokens;  // the text of each number
  std::size_t pos = 0;
  bool after_comma = false;
  for (;;) {
    while (pos < t.size() && is_space(t[pos])) ++pos;
    if (pos >= t.size()) break;
    double v = 0;
    const std::size_t n = read_number(t.substr(pos), v);
    if (n == 0) break;
    if (!std::isfinite(v)) {
      throw std::invalid_argument("number out of range in '" + std::string(text) + "'");
    }
    numbers.push_back(v);
    tokens.push_back(t.substr(pos, n));
    pos += n;
    after_comma = false;
    while (pos < t.size() && is_space(t[pos])) ++pos;
    if (pos < t.size() && t[pos] == ',') {
      ++pos;
      after_comma = true;
    }
  }
  std::string_view unit = trim(t.substr(std::min(pos, t.size())));
  if (after_comma) {
    throw std::invalid_argument("expected a number after ',' in '" + std::string(text) + "'");
  }
  // "1 1 1 1/s": the last "1" belongs to the unit.
  if (!unit.empty() && unit.front() == '/' && !tokens.empty() && tokens.back() == "1") {
    const char* begin = tokens.back().data();
    unit = trim(std::string_view(begin, static_cast<std::size_t>(t.data() + t.size() - begin)));
    numbers.pop_back();
    tokens.pop_back();
  }
  if (numbers.empty()) {
    throw std::invalid_argument("expected numbers at the start of '" + std::string(text) + "'");
  }
  Quantity factor{1.0, dim::none};
  if (!unit.empty()) {
    if (unit.front() == ',') {
      throw std::invalid_argument("unexpected ',' in '" + std::string(text) + "'");
    }
    factor = parse_unit_in(unit, text);
  }
  std::vector<Quantity> out;
  out.reserve(numbers.size());
  for (double v : numbers) out.push_back({v * factor.value, factor.dim});
  return out;
}

std::string describe(const Dimension& d) {
  struct Named {
    Dimension dim;
    std::string_view text;
  };
  static constexpr Named kNames[] = {
      {dim::none, "a dimensionless number"},
      {dim::length, "a length (m)"},
      {dim::time, "a time (s)"},
      {dim::mass, "a mass (kg)"},
      {dim::temperature, "a temperature (K)"},
      {dim::velocity, "a velocity (m/s)"},
      {dim::acceleration, "an acceleration (m/s^2)"},
      {dim::density, "a density (kg/m^3)"},
      {dim::pressure, "a pressure (Pa)"},
      {dim::force, "a force (N)"},
      {dim::energy, "an energy (J)"},
      {dim::rate, "a rate (1/s)"},
      {dim::specific_heat, "a specific heat (J/(kg*K))"},
      {dim::specific_energy, "a specific energy (J/kg)"},
  };
  for (const auto& n : kNames) {
    if (n.dim == d) return std::string(n.text);
  }
  std::string s = "a quantity in";
  const auto term = [&s](const char* sym, int e) {
    if (e == 0) return;
    s += ' ';
    s += sym;
    if (e != 1) {
      s += '^';
      s += std::to_string(e);
    }
  };
  term("kg", d.M);
  term("m", d.L);
  term("s", d.T);
  term("K", d.K);
  return s;
}

std::string format_mm(double metres) {
  char b[32];
  std::snprintf(b, sizeof b, "%.6g", metres * 1e3);
  return b;
}

std::string format_g6(double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

std::string format_count(double n) {
  char buf[64];
  if (n < 1e18)
    std::snprintf(buf, sizeof buf, "%.0f", n);
  else
    std::snprintf(buf, sizeof buf, "%.3g", n);
  return buf;
}

}  // namespace mpm
