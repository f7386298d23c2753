// Scene file parser: TOML (toml++) -> Scene. Reference for users: docs/scene.md.
//
// Every table is read through a Reader that knows the keys the table accepts (anything else is
// reported as an unknown key), converts values to typed SI values and produces error messages
// that name the file, the line and the dotted key. To add a key: add its name to the key list
// of its table and read it where the table is read; Reader::finish() catches a listed key that
// is never read.
#include "mpm/scene/scene.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <climits>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iostream>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>
#include <system_error>
#include <unordered_map>
#include <utility>

#include "mpm/core/error.hpp"
#include "mpm/core/units.hpp"

namespace mpm {
namespace {

using namespace std::string_literals;

/// Which side of zero a value must be on.
enum class Bound { Any, Positive, NonNegative, Negative };

/// Where a value came from: a line of the scene file, or a --set override.
struct Origin {
  std::string set;  ///< the --set key when the value came from an override, else empty
  int line = 0;     ///< line in the scene file, 0 when unknown
};

/// The parsed document's context: the file name and which nodes the overrides created.
struct Doc {
  std::string file;
  std::unordered_map<const toml::node*, std::string> set_by;  ///< node -> --set key

  /// "scene.toml:12: materials.copper.density", or "--set solver.cfl".
  std::string where(const Origin& o, const std::string& path) const {
    if (!o.set.empty()) return mpm::where("--set " + o.set, 0, o.set == path ? "" : path);
    return mpm::where(file, o.line, path);
  }

  /// Origin of a node found inside a table whose origin is `parent`.
  Origin origin(const toml::node& n, const Origin& parent) const {
    if (auto it = set_by.find(&n); it != set_by.end()) return {it->second, 0};
    if (!parent.set.empty()) return parent;  // inside a table that an override created
    const int line = static_cast<int>(n.source().begin.line);
    return {"", line > 0 ? line : parent.line};
  }

  /// Marks a node and everything below it as coming from the override `key`.
  void record(const toml::node& n, const std::string& key) {
    set_by[&n] = key;
    if (const auto* t = n.as_table()) {
      for (auto&& [k, v] : *t) record(v, key);
    } else if (const auto* a = n.as_array()) {
      for (const auto& e : *a) record(e, key);
    }
  }
};

std::string type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a floating-point number";
    case toml::node_type::boolean:
      return "a boolean";
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::date:
      return "a date";
    case toml::node_type::time:
      return "a time";
    case toml::node_type::date_time:
      return "a date-time";
    default:
      return "nothing";
  }
}

std::string format_number(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

/// The value as the user wrote it, for messages: strings quoted, numbers as numbers.
std::string show(const toml::node& n) {
  if (const auto* s = n.as_string()) return "'" + s->get() + "'";
  if (const auto* i = n.as_integer()) return std::to_string(i->get());
  if (const auto* f = n.as_floating_point()) return format_number(f->get());
  if (const auto* b = n.as_boolean()) return b->get() ? "true" : "false";
  return type_name(n);
}

/// "got 3 (an integer)", "got a table".
std::string got(const toml::node& n) {
  if (n.is_table() || n.is_array()) return "got " + type_name(n);
  return "got " + show(n) + " (" + type_name(n) + ")";
}

/// "a density" from "a density (kg/m^3)".
std::string dim_name(const Dimension& d) {
  const std::string s = describe(d);
  const auto p = s.find(" (");
  return p == std::string::npos ? s : s.substr(0, p);
}

/// What a scalar key expects, for messages.
std::string expectation(const Dimension& d, bool angle) {
  if (angle) return "an angle (a number in degrees, or a string with deg or rad)";
  if (d == dim::none) return "a number";
  return describe(d);
}

/// True unless the text ends with a plain number ("1 2 3", "1e3" have no unit; "3 mm",
/// "117GPa", "1 1/s" have one). Unit-less strings are taken as SI, like plain numbers.
bool has_unit(std::string_view text) {
  const auto end = text.find_last_not_of(" \t");
  if (end == std::string_view::npos) return false;
  text = text.substr(0, end + 1);
  const auto start = text.find_last_of(" \t,");
  std::string_view token = start == std::string_view::npos ? text : text.substr(start + 1);
  if (!token.empty() && (token.front() == '+' || token.front() == '-')) token.remove_prefix(1);
  double v = 0;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
  return !(ec == std::errc() && ptr == token.data() + token.size());
}

std::string join(const std::vector<std::string_view>& items, std::string_view sep = ", ") {
  std::string s;
  for (const auto& i : items) {
    if (!s.empty()) s += sep;
    s += i;
  }
  return s;
}

/// Reads one TOML table: checks for unknown keys, converts values, reports mistakes.
class Reader {
 public:
  /// `keys` are all the keys the table accepts; any other key is an error right away.
  Reader(const Doc& doc, const toml::table& table, std::string path, Origin origin,
         std::vector<std::string_view> keys)
      : doc_(&doc),
        table_(&table),
        path_(std::move(path)),
        origin_(std::move(origin)),
        keys_(std::move(keys)) {
    // Report the first unknown key in file order (the table itself is sorted by name).
    const toml::key* bad = nullptr;
    long bad_line = LONG_MAX;
    for (auto&& [k, v] : table) {
      if (std::find(keys_.begin(), keys_.end(), k.str()) != keys_.end()) continue;
      const long line = v.source().begin.line > 0 ? long(v.source().begin.line) : LONG_MAX - 1;
      if (!bad || line < bad_line) {
        bad = &k;
        bad_line = line;
      }
    }
    if (bad) fail(bad->str(), "unknown key (expected one of: " + join(keys_) + ")");
  }

  const std::string& path() const { return path_; }
  const Origin& origin() const { return origin_; }
  const Doc& doc() const { return *doc_; }
  const toml::table& table() const { return *table_; }

  /// Dotted path of a key of this table.
  std::string key_path(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
  }

  /// Where the table is, as a SourceLoc for the structs.
  SourceLoc loc() const {
    if (!origin_.set.empty()) return {"--set " + origin_.set, 0, path_};
    return {doc_->file, origin_.line, path_};
  }

  /// Where a key's value is (its line, or the --set that gave it), as a SourceLoc for the
  /// structs; mpm::where(loc.file, loc.line, loc.key) names it as Doc::where does.
  SourceLoc loc_of(std::string_view key) const {
    const toml::node* n = table_->get(key);
    const Origin o = n ? origin_of(*n) : origin_;
    const std::string path = key_path(key);
    if (!o.set.empty()) return {"--set " + o.set, 0, o.set == path ? "" : path};
    return {doc_->file, o.line, path};
  }

  /// The key's value, or nullptr. Marks the key as read.
  const toml::node* get(std::string_view key) {
    if (std::find(keys_.begin(), keys_.end(), key) == keys_.end()) {
      throw std::logic_error("scene parser reads key '" + key_path(key) +
                             "' that is not in its key list");
    }
    read_.insert(std::string(key));
    return table_->get(key);
  }

  bool has(std::string_view key) const { return table_->contains(key); }

  /// Origin of a node inside this table.
  Origin origin_of(const toml::node& n) const { return doc_->origin(n, origin_); }

  /// Fails at a key: at its value when present (or at `node`), else at the table.
  [[noreturn]] void fail(std::string_view key, const std::string& message,
                         const toml::node* node = nullptr) const {
    if (!node) node = table_->get(key);
    const Origin o = node ? origin_of(*node) : origin_;
    throw InputError(doc_->where(o, key_path(key)), message);
  }

  /// Fails at the table itself.
  [[noreturn]] void fail_table(const std::string& message) const {
    throw InputError(doc_->where(origin_, path_), message);
  }

  /// "missing required key 'density' (a density, e.g. "8930 kg/m^3")".
  [[noreturn]] void missing(std::string_view key, const std::string& what) const {
    fail_table("missing required key '" + std::string(key) + "' (" + what + ")");
  }

  /// Fails with `message` + ", got <value>" unless `ok`.
  void check(std::string_view key, bool ok, const std::string& message) const {
    if (ok) return;
    const toml::node* n = table_->get(key);
    fail(key, n ? message + ", got " + show(*n) : message);
  }

  /// Rejects keys that the chosen model or shape does not use.
  void reject(std::initializer_list<std::string_view> keys, const std::string& why) {
    for (auto key : keys) {
      if (get(key)) fail(key, "not used " + why);
    }
  }

  /// A scalar value in SI (or degrees when `angle`): a number, or a string with a unit.
  double scalar(const toml::node& n, std::string_view key, const Dimension& d, bool angle) const {
    const std::string expect = expectation(d, angle);
    if (n.is_integer() || n.is_floating_point()) {
      const double v = *n.value<double>();
      if (!std::isfinite(v)) fail(key, "expected a finite number, got " + show(n), &n);
      return v;
    }
    if (const auto* s = n.as_string()) {
      const std::string& text = s->get();
      const auto first = text.find_first_not_of(" \t");
      if (first == std::string::npos ||
          std::string_view("0123456789+-.").find(text[first]) == std::string_view::npos) {
        fail(key, "expected " + expect + ", " + got(n), &n);
      }
      Quantity q;
      try {
        q = parse_quantity(text);
      } catch (const std::invalid_argument& e) {
        fail(key, "expected " + expect + ": " + e.what(), &n);
      }
      if (!has_unit(text)) return q.value;
      if (!(q.dim == d)) {
        fail(key, "expected " + expect + ", got '" + text + "' (" + dim_name(q.dim) + ")", &n);
      }
      if (d == dim::none && !angle) {
        fail(key, "expected a plain number without a unit, got '" + text + "'", &n);
      }
      return angle ? q.value * 180.0 / std::numbers::pi : q.value;
    }
    fail(key, "expected " + expect + ", " + got(n), &n);
  }

  void check_bound(std::string_view key, double v, Bound b, const toml::node& n,
                   std::string_view every = "") const {
    const char* rule = nullptr;
    if (b == Bound::Positive && !(v > 0)) rule = "must be > 0";
    if (b == Bound::NonNegative && !(v >= 0)) rule = "must be >= 0";
    if (b == Bound::Negative && !(v < 0)) rule = "must be < 0";
    if (rule) fail(key, std::string(every) + rule + ", got " + show(n), &n);
  }

  /// A quantity in SI, nullopt when absent. A plain number is taken as SI.
  std::optional<double> quantity(std::string_view key, const Dimension& d, Bound b = Bound::Any) {
    const toml::node* n = get(key);
    if (!n) return std::nullopt;
    const double v = scalar(*n, key, d, false);
    check_bound(key, v, b, *n);
    return v;
  }

  /// A dimensionless number.
  std::optional<double> number(std::string_view key, Bound b = Bound::Any) {
    return quantity(key, dim::none, b);
  }

  /// An angle in degrees: a number (degrees) or "30 deg", "0.5 rad".
  std::optional<double> angle(std::string_view key) {
    const toml::node* n = get(key);
    if (!n) return std::nullopt;
    return scalar(*n, key, dim::none, true);
  }

  /// A required quantity; `example` is shown when it is missing ("8930 kg/m^3").
  double required(std::string_view key, const Dimension& d, Bound b, std::string_view example,
                  std::string_view note = "") {
    if (auto v = quantity(key, d, b)) return *v;
    const std::string ex =
        d == dim::none ? std::string(example) : "\"" + std::string(example) + "\"";
    missing(key, (d == dim::none ? "a number"s : dim_name(d)) + ", e.g. " + ex +
                     (note.empty() ? "" : "; " + std::string(note)));
  }

  /// An integer in [lo, hi].
  std::optional<long long> integer(std::string_view key, long long lo = LLONG_MIN,
                                   long long hi = LLONG_MAX) {
    const toml::node* n = get(key);
    if (!n) return std::nullopt;
    const auto* i = n->as_integer();
    if (!i) fail(key, "expected an integer, " + got(*n));
    const long long v = i->get();
    if (v < lo || v > hi) {
      std::string rule;
      if (hi == LLONG_MAX) {
        rule = "must be >= " + std::to_string(lo);
      } else if (lo == LLONG_MIN) {
        rule = "must be <= " + std::to_string(hi);
      } else {
        rule = "must be between " + std::to_string(lo) + " and " + std::to_string(hi);
      }
      fail(key, rule + ", got " + std::to_string(v));
    }
    return v;
  }

  std::optional<std::string> string(std::string_view key) {
    const toml::node* n = get(key);
    if (!n) return std::nullopt;
    const auto* s = n->as_string();
    if (!s) fail(key, "expected a string, " + got(*n));
    return s->get();
  }

  std::optional<bool> boolean(std::string_view key) {
    const toml::node* n = get(key);
    if (!n) return std::nullopt;
    const auto* b = n->as_boolean();
    if (!b) fail(key, "expected true or false, " + got(*n));
    return b->get();
  }

  /// One of a fixed set of strings, mapped to an enum.
  template <class E>
  std::optional<E> choice(std::string_view key,
                          std::initializer_list<std::pair<std::string_view, E>> options,
                          bool ignore_case = false) {
    const auto text = string(key);
    if (!text) return std::nullopt;
    const auto same = [ignore_case](std::string_view a, std::string_view b) {
      if (a.size() != b.size()) return false;
      for (std::size_t i = 0; i < a.size(); ++i) {
        const char x = ignore_case ? char(std::tolower(static_cast<unsigned char>(a[i]))) : a[i];
        const char y = ignore_case ? char(std::tolower(static_cast<unsigned char>(b[i]))) : b[i];
        if (x != y) return false;
      }
      return true;
    };
    std::vector<std::string_view> names;
    for (const auto& [name, value] : options) {
      if (same(name, *text)) return value;
      names.push_back(name);
    }
    fail(key, "expected one of \"" + join(names, "\", \"") + "\", got '" + *text + "'");
  }

  /// A vector of n components in SI (degrees when `angle`), as "x y z unit" or an array of
  /// numbers or quantity strings. With `broadcast`, one value stands for all n components.
  std::optional<Vec3> vector(std::string_view key, const Dimension& d, int n, Bound b = Bound::Any,
                             bool angle = false, bool broadcast = false) {
    const toml::node* node = get(key);
    if (!node) return std::nullopt;
    const std::string axes = n == 3 ? "x y z" : "x y";
    const std::string expect = "a vector of " + std::to_string(n) + " components (" + axes +
                               "), each " + expectation(d, angle) + ", as a string \"" + axes +
                               " unit\" or an array";
    std::vector<double> comps;
    if (const auto* s = node->as_string()) {
      std::vector<Quantity> qs;
      try {
        qs = parse_vector(s->get());
      } catch (const std::invalid_argument& e) {
        fail(key, "expected " + expect + ": " + e.what());
      }
      const bool unit = has_unit(s->get());
      if (unit && !(qs.front().dim == d)) {
        fail(key,
             "expected " + expect + ", got " + show(*node) + " (" + dim_name(qs.front().dim) + ")");
      }
      if (unit && d == dim::none && !angle) {
        fail(key, "expected plain numbers without a unit, got " + show(*node));
      }
      for (const auto& q : qs) {
        comps.push_back(unit && angle ? q.value * 180.0 / std::numbers::pi : q.value);
      }
    } else if (const auto* a = node->as_array()) {
      for (std::size_t i = 0; i < a->size(); ++i) {
        comps.push_back(
            scalar((*a)[i], std::string(key) + "[" + std::to_string(i) + "]", d, angle));
      }
    } else if (broadcast && (node->is_integer() || node->is_floating_point())) {
      comps.push_back(scalar(*node, key, d, angle));
    } else {
      fail(key, "expected " + expect + ", " + got(*node));
    }
    if (broadcast && comps.size() == 1) comps.assign(n, comps.front());
    if (static_cast<int>(comps.size()) != n) {
      fail(key, "expected " + std::to_string(n) + " components (" + axes + "), got " +
                    std::to_string(comps.size()) +
                    (node->is_string() ? " in " + show(*node) : std::string()));
    }
    Vec3 v = Vec3::Zero();
    for (int i = 0; i < n; ++i) {
      v[i] = comps[i];
      check_bound(key, comps[i], b, *node, "every component ");
    }
    return v;
  }

  /// A sub-table, nullopt when absent.
  std::optional<Reader> table(std::string_view key, std::vector<std::string_view> keys) {
    const toml::node* n = get(key);
    if (!n) return std::nullopt;
    const auto* t = n->as_table();
    if (!t) fail(key, "expected a table, " + got(*n));
    return Reader(*doc_, *t, key_path(key), origin_of(*n), std::move(keys));
  }

  /// A required sub-table.
  Reader required_table(std::string_view key, std::vector<std::string_view> keys,
                        std::string_view note) {
    if (auto r = table(key, std::move(keys))) return std::move(*r);
    fail(key, "missing required table [" + key_path(key) + "] (" + std::string(note) + ")");
  }

  /// Checks that every accepted key present was read (a parser bug otherwise).
  void finish() const {
    for (auto&& [k, v] : *table_) {
      if (!read_.count(std::string(k.str()))) {
        throw std::logic_error("scene parser accepted but did not read '" + key_path(k.str()) +
                               "'");
      }
    }
  }

 private:
  const Doc* doc_;
  const toml::table* table_;
  std::string path_;
  Origin origin_;
  std::vector<std::string_view> keys_;
  std::set<std::string> read_;
};

// ---------------------------------------------------------------------------------------------
// Materials

void read_strength(Reader& r, StrengthSpec& s) {
  s.model = r.choice<StrengthModel>("model", {{"elastic", StrengthModel::Elastic},
                                              {"j2", StrengthModel::J2},
                                              {"johnson-cook", StrengthModel::JohnsonCook}})
                .value_or(StrengthModel::Elastic);
  const std::initializer_list<std::string_view> jc_only = {"C",
                                                           "reference_rate",
                                                           "m",
                                                           "room_temperature",
                                                           "melt_temperature",
                                                           "specific_heat",
                                                           "taylor_quinney"};
  if (s.model == StrengthModel::Elastic) {
    r.reject({"A", "B", "n"}, "by the elastic model (set model = \"j2\" or \"johnson-cook\")");
    r.reject(jc_only, "by the elastic model (set model = \"johnson-cook\")");
    r.finish();
    return;
  }
  s.A = r.required("A", dim::pressure, Bound::NonNegative, "157 MPa");
  s.B = r.quantity("B", dim::pressure, Bound::NonNegative).value_or(0.0);
  s.n = r.number("n", Bound::Positive).value_or(1.0);
  if (s.model == StrengthModel::J2) {
    r.reject(jc_only, "by the j2 model (only by \"johnson-cook\")");
    r.finish();
    return;
  }
  s.C = r.number("C", Bound::NonNegative).value_or(0.0);
  s.reference_rate = r.quantity("reference_rate", dim::rate, Bound::Positive).value_or(1.0);
  s.m = r.number("m", Bound::NonNegative).value_or(0.0);
  s.room_temperature =
      r.quantity("room_temperature", dim::temperature, Bound::Positive).value_or(293.0);
  if (s.m > 0) {
    s.melt_temperature = r.required("melt_temperature", dim::temperature, Bound::Positive, "1356 K",
                                    "required when m > 0");
    s.specific_heat = r.required("specific_heat", dim::specific_heat, Bound::Positive,
                                 "383 J/(kg*K)", "required when m > 0");
  } else {
    if (auto v = r.quantity("melt_temperature", dim::temperature, Bound::Positive)) {
      s.melt_temperature = *v;
    }
    if (auto v = r.quantity("specific_heat", dim::specific_heat, Bound::Positive)) {
      s.specific_heat = *v;
    }
  }
  if (r.has("melt_temperature")) {
    r.check("melt_temperature", s.melt_temperature > s.room_temperature,
            "must be above room_temperature (" + format_number(s.room_temperature) + " K)");
  }
  s.taylor_quinney = r.number("taylor_quinney").value_or(0.9);
  r.check("taylor_quinney", s.taylor_quinney >= 0 && s.taylor_quinney <= 1,
          "must be between 0 and 1");
  r.finish();
}

void read_eos(Reader& r, EosSpec& e) {
  e.model = r.choice<EosModel>(
                 "model", {{"linear", EosModel::Linear}, {"mie-gruneisen", EosModel::MieGruneisen}})
                .value_or(EosModel::Linear);
  if (e.model == EosModel::Linear) {
    r.reject({"c0", "s", "gamma0", "energy_in_expansion"},
             "by the linear model (set model = \"mie-gruneisen\")");
  } else {
    e.c0 = r.required("c0", dim::velocity, Bound::Positive, "3940 m/s");
    e.s = r.required("s", dim::none, Bound::NonNegative, "1.49");
    e.gamma0 = r.required("gamma0", dim::none, Bound::NonNegative, "1.96");
    e.energy_in_expansion = r.boolean("energy_in_expansion").value_or(true);
  }
  r.finish();
}

void read_failure(Reader& r, FailureSpec& f) {
  if (r.table().empty()) {
    r.fail_table("empty table: give plastic_strain, pressure or both (or remove the table)");
  }
  if (auto v = r.number("plastic_strain", Bound::Positive)) f.plastic_strain = *v;
  if (auto v = r.quantity("pressure", dim::pressure, Bound::Negative)) f.pressure = *v;
  r.finish();
}

MaterialSpec read_material(Reader& r, const std::string& name) {
  MaterialSpec m;
  m.name = name;
  m.loc = r.loc();
  m.density = r.required("density", dim::density, Bound::Positive, "8930 kg/m^3");
  m.youngs_modulus = r.required("youngs_modulus", dim::pressure, Bound::Positive, "117 GPa");
  m.poisson_ratio = r.required("poisson_ratio", dim::none, Bound::Any, "0.35");
  r.check("poisson_ratio", m.poisson_ratio > -1, "must be above -1");
  r.check("poisson_ratio", m.poisson_ratio < 0.5,
          "must be below 0.5 (incompressible materials are not supported)");
  if (auto t = r.table("strength",
                       {"model", "A", "B", "n", "C", "reference_rate", "m", "room_temperature",
                        "melt_temperature", "specific_heat", "taylor_quinney"})) {
    read_strength(*t, m.strength);
  }
  if (auto t = r.table("eos", {"model", "c0", "s", "gamma0", "energy_in_expansion"}))
    read_eos(*t, m.eos);
  if (auto t = r.table("failure", {"plastic_strain", "pressure"})) read_failure(*t, m.failure);
  r.finish();
  return m;
}

// ---------------------------------------------------------------------------------------------
// Bodies

bool valid_name(std::string_view s) {
  if (s.empty()) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-';
  });
}

const std::vector<std::string_view> kBodyKeys = {"name",
                                                 "material",
                                                 "shape",
                                                 "size",
                                                 "radius",
                                                 "length",
                                                 "file",
                                                 "scale",
                                                 "rotate",
                                                 "translate",
                                                 "velocity",
                                                 "particles_per_cell",
                                                 "particle_spacing",
                                                 "rigid",
                                                 "slip"};

BodySpec read_body(Reader& r, const Scene& scene) {
  const int n = scene.dimension;
  const bool two_d = n == 2;
  BodySpec b;
  b.name = *r.string("name");
  b.loc = r.loc();

  b.rigid = r.boolean("rigid").value_or(false);
  const auto material = r.string("material");
  if (b.rigid) {
    if (material)
      r.fail("material",
             "a rigid body has no material (it moves at its velocity whatever happens)");
  } else if (!material) {
    r.missing("material", "the name of a material, e.g. \"copper\"");
  }
  b.material = material ? scene.material_index(*material) : -1;
  if (!b.rigid && b.material < 0) {
    std::vector<std::string_view> known;
    for (const auto& m : scene.materials) known.push_back(m.name);
    r.fail("material", "unknown material '" + *material + "' (known: " + join(known) + ")");
  }

  const auto shape = r.choice<ShapeKind>("shape", {{"box", ShapeKind::Box},
                                                   {"cylinder", ShapeKind::Cylinder},
                                                   {"sphere", ShapeKind::Sphere},
                                                   {"mesh", ShapeKind::Mesh}});
  if (!shape) r.missing("shape", "one of \"box\", \"cylinder\", \"sphere\", \"mesh\"");
  b.shape = *shape;
  if (two_d && (b.shape == ShapeKind::Cylinder || b.shape == ShapeKind::Mesh)) {
    r.fail("shape", "shape \"" + *r.string("shape") +
                        "\" is not available in 2D scenes; use box or sphere (a disk)");
  }
  const std::string shape_name = *r.string("shape");
  const auto not_for = [&](std::string_view applies) {
    return "with shape = \"" + shape_name + "\" (this key is for " + std::string(applies) + ")";
  };
  switch (b.shape) {
    case ShapeKind::Box:
      if (auto v = r.vector("size", dim::length, n, Bound::Positive)) {
        b.size = *v;
      } else {
        r.missing("size", two_d ? "edge lengths x y, e.g. \"10 5 mm\""
                                : "edge lengths x y z, e.g. \"10 10 5 mm\"");
      }
      r.reject({"radius"}, not_for("cylinder and sphere"));
      r.reject({"length"}, not_for("cylinder"));
      r.reject({"file"}, not_for("mesh"));
      break;
    case ShapeKind::Cylinder:
      b.radius = r.required("radius", dim::length, Bound::Positive, "3.8 mm");
      b.length = r.required("length", dim::length, Bound::Positive, "25.4 mm");
      r.reject({"size"}, not_for("box"));
      r.reject({"file"}, not_for("mesh"));
      break;
    case ShapeKind::Sphere:
      b.radius = r.required("radius", dim::length, Bound::Positive, "3.8 mm");
      r.reject({"size"}, not_for("box"));
      r.reject({"length"}, not_for("cylinder"));
      r.reject({"file"}, not_for("mesh"));
      break;
    case ShapeKind::Mesh: {
      const auto file = r.string("file");
      if (!file) r.missing("file", "the mesh file (STL, OFF or OBJ), e.g. \"part.stl\"");
      r.check("file", !file->empty(), "must not be empty");
      const std::filesystem::path p(*file);
      b.mesh_path = (p.is_absolute() || scene.directory.empty())
                        ? p.string()
                        : (std::filesystem::path(scene.directory) / p).string();
      r.reject({"size"}, not_for("box"));
      r.reject({"radius"}, not_for("cylinder and sphere"));
      r.reject({"length"}, not_for("cylinder"));
      break;
    }
  }

  if (auto v = r.vector("scale", dim::none, n, Bound::Positive, false, true)) b.scale = *v;
  if (two_d) b.scale.z() = 1.0;
  if (two_d) {
    const toml::node* rot = r.get("rotate");
    if (rot && !(rot->is_integer() || rot->is_floating_point() || rot->is_string())) {
      r.fail("rotate",
             "expected a single angle about z in 2D scenes, e.g. \"30 deg\", " + got(*rot));
    }
    if (rot && rot->is_string()) {
      try {
        (void)parse_quantity(rot->as_string()->get());
      } catch (const std::invalid_argument& e) {
        r.fail("rotate",
               "expected a single angle about z in 2D scenes, e.g. \"30 deg\": "s + e.what());
      }
    }
    if (auto a = r.angle("rotate")) b.rotate_deg = Vec3(0, 0, *a);
  } else if (auto v = r.vector("rotate", dim::none, 3, Bound::Any, true)) {
    b.rotate_deg = *v;
  }
  if (auto v = r.vector("translate", dim::length, n)) b.translate = *v;
  if (auto v = r.vector("velocity", dim::velocity, n)) b.velocity = *v;
  b.particles_per_cell = static_cast<int>(r.integer("particles_per_cell", 1, 8).value_or(2));
  if (auto sp = r.quantity("particle_spacing", dim::length, Bound::Positive)) {
    // One or the other (a --set of one removes the other: apply_override).
    if (r.has("particles_per_cell"))
      r.fail("particle_spacing",
             "give either particles_per_cell (the spacing is the cell size over it) or "
             "particle_spacing, not both");
    b.particle_spacing = *sp;
    b.spacing_loc = r.loc_of("particle_spacing");
  }
  if (auto slip = r.string("slip")) {
    // The axes along which a rigid body's contact is frictionless: "y", "x z", "xz"; "none":
    // no-slip (the default, for --set).
    const std::string axes = two_d ? "x y" : "x y z";
    if (!b.rigid)
      r.fail("slip", "only a rigid body has a contact to slip on (this body has a material)");
    for (char c : *slip == "none" ? std::string() : *slip) {
      if (c == ' ' || c == ',') continue;
      const int a = c - 'x';
      if (a < 0 || a >= n)
        r.fail("slip", "expected the axes along which the contact is frictionless, from " + axes +
                           ", e.g. \"y\"; got '" + std::string(1, c) + "' in \"" + *slip + "\"");
      b.slip_axes |= std::uint8_t(1u << a);
    }
    if (b.slip_axes == 0 && *slip != "none")
      r.fail("slip", "expected at least one axis from " + axes + ", e.g. \"y\", or \"none\"");
    if (b.slip_axes == (1u << n) - 1)
      r.fail("slip", "a body that slips along every axis holds nothing; leave one axis out");
  }
  r.finish();
  return b;
}

void read_bodies(Reader& top, Scene& s) {
  const toml::node* node = top.get("bodies");
  if (!node) {
    top.fail("bodies", "missing required array [[bodies]] (at least one body)");
  }
  const auto* arr = node->as_array();
  if (!arr) {
    top.fail("bodies",
             "expected an array of tables ([[bodies]], note the double brackets), " + got(*node));
  }
  if (arr->empty()) top.fail("bodies", "at least one body is required");
  const Doc& doc = top.doc();
  const Origin array_origin = top.origin_of(*node);
  std::map<std::string, std::string> seen;  // name -> where
  for (std::size_t i = 0; i < arr->size(); ++i) {
    const toml::node& e = (*arr)[i];
    const std::string index_path = "bodies[" + std::to_string(i) + "]";
    const Origin o = doc.origin(e, array_origin);
    const auto* t = e.as_table();
    if (!t) throw InputError(doc.where(o, index_path), "expected a table ([[bodies]]), " + got(e));
    const toml::node* name = t->get("name");
    if (!name) {
      throw InputError(doc.where(o, index_path),
                       "missing required key 'name' (letters, digits, '_' and '-', e.g. \"bar\")");
    }
    const Origin name_origin = doc.origin(*name, o);
    const auto* name_str = name->as_string();
    if (!name_str) {
      throw InputError(doc.where(name_origin, index_path + ".name"),
                       "expected a string, " + got(*name));
    }
    if (!valid_name(name_str->get())) {
      throw InputError(
          doc.where(name_origin, index_path + ".name"),
          "a body name may contain only letters, digits, '_' and '-', got " + show(*name));
    }
    const std::string path = "bodies." + name_str->get();
    if (auto it = seen.find(name_str->get()); it != seen.end()) {
      throw InputError(
          doc.where(name_origin, path + ".name"),
          "duplicate body name '" + name_str->get() + "' (first used at " + it->second + ")");
    }
    seen[name_str->get()] = doc.where(name_origin, "");
    Reader r(doc, *t, path, o, kBodyKeys);
    s.bodies.push_back(read_body(r, s));
  }
}

// ---------------------------------------------------------------------------------------------
// Loads

void read_loads(Reader& top, Scene& s) {
  const toml::node* node = top.get("loads");
  if (!node) return;
  const auto* arr = node->as_array();
  if (!arr) {
    top.fail("loads",
             "expected an array of tables ([[loads]], note the double brackets), " + got(*node));
  }
  const Doc& doc = top.doc();
  const Origin array_origin = top.origin_of(*node);
  for (std::size_t i = 0; i < arr->size(); ++i) {
    const toml::node& e = (*arr)[i];
    const std::string path = "loads." + std::to_string(i);
    const Origin o = doc.origin(e, array_origin);
    const auto* t = e.as_table();
    if (!t) throw InputError(doc.where(o, path), "expected a table ([[loads]]), " + got(e));
    Reader r(doc, *t, path, o, {"body", "force", "region"});
    LoadSpec l;
    l.loc = r.loc();
    const auto body = r.string("body");
    if (!body) r.missing("body", "the name of the body the force acts on, e.g. \"rod\"");
    l.body = s.body_index(*body);
    if (l.body < 0) {
      std::vector<std::string_view> known;
      for (const auto& b : s.bodies) known.push_back(b.name);
      r.fail("body", "unknown body '" + *body + "' (known: " + join(known) + ")");
    }
    if (s.bodies[l.body].rigid) r.fail("body", "a rigid body cannot carry a load");
    const auto f = r.vector("force", dim::force, s.dimension);
    if (!f)
      r.missing("force", s.dimension == 2 ? "the total force, e.g. \"2.5 0 N\""
                                          : "the total force, e.g. \"2.5 0 0 N\"");
    l.force = *f;
    if (auto reg = r.table("region", {"min", "max"})) {
      const auto lo = reg->vector("min", dim::length, s.dimension);
      const auto hi = reg->vector("max", dim::length, s.dimension);
      if (!lo) reg->missing("min", "the region's minimum corner");
      if (!hi) reg->missing("max", "the region's maximum corner");
      for (int a = 0; a < s.dimension; ++a)
        reg->check("max", (*hi)[a] > (*lo)[a], "must exceed region.min in every component");
      l.region_given = true;
      l.region_min = *lo;
      l.region_max = *hi;
      reg->finish();
    }
    r.finish();
    s.loads.push_back(l);
  }
}

// ---------------------------------------------------------------------------------------------
// Grid, boundary, solver, output

/// [[grid.levels]]: the refined boxes of a graded grid (004, section 3.1). Alignment to the
/// coarser lattice and the domain are checked here; nesting and the one-level rule between
/// neighbouring cells when the grid is built (graded_grid.cpp), naming the same keys.
void read_levels(Reader& grid, Scene& s) {
  const toml::node* node = grid.get("levels");
  if (!node) return;
  const int n = s.dimension;
  const GridSpec& g = s.grid;
  const auto* arr = node->as_array();
  if (!arr)
    grid.fail(
        "levels",
        "expected an array of tables ([[grid.levels]], note the double brackets), " + got(*node));
  if (!g.domain_given)
    grid.fail("levels",
              "level boxes need grid.domain: they are aligned to the lattice that starts "
              "at domain.min");
  const Doc& doc = grid.doc();
  const Origin array_origin = grid.origin_of(*node);
  for (std::size_t i = 0; i < arr->size(); ++i) {
    const toml::node& e = (*arr)[i];
    const std::string path = "grid.levels." + std::to_string(i);
    const Origin o = doc.origin(e, array_origin);
    const auto* t = e.as_table();
    if (!t) throw InputError(doc.where(o, path), "expected a table ([[grid.levels]]), " + got(e));
    Reader r(doc, *t, path, o, {"level", "min", "max", "follow"});
    LevelSpec l;
    l.loc = r.loc();
    const auto level = r.integer("level", 2, 12);
    if (!level) r.missing("level", "2 for cells of half the grid.cell_size, 3 for a quarter, ...");
    l.level = int(*level);
    const std::string ex = n == 3 ? "\"-4 -4 0 mm\"" : "\"-4 0 mm\"";
    const auto lo = r.vector("min", dim::length, n);
    if (!lo) r.missing("min", "the box's lower corner, e.g. " + ex);
    const auto hi = r.vector("max", dim::length, n);
    if (!hi) r.missing("max", "the box's upper corner");
    l.min = *lo;
    l.max = *hi;
    const double hp = std::ldexp(g.cell_size, -(l.level - 2));  // the coarser level's cells
    for (int a = 0; a < n; ++a) {
      const std::string axis(1, "xyz"[a]);
      r.check("max", l.max[a] > l.min[a], "must exceed min in every component");
      for (const char* key : {"min", "max"}) {
        const double v = std::string_view(key) == "min" ? l.min[a] : l.max[a];
        if (v < g.domain_min[a] - 1e-9 * hp || v > g.domain_max[a] + 1e-9 * hp)
          r.fail(key, "the box leaves grid.domain along " + axis);
        const double cells = (v - g.domain_min[a]) / hp;
        if (std::abs(cells - std::round(cells)) > 1e-6)
          r.fail(key, "a level-" + std::to_string(l.level) + " box must lie on the level-" +
                          std::to_string(l.level - 1) + " lattice: " + axis + " = " +
                          format_number(v * 1e3) + " mm is not a multiple of " +
                          format_number(hp * 1e3) + " mm from grid.domain.min (nearest: " +
                          format_number((g.domain_min[a] + hp * std::round(cells)) * 1e3) + " mm)");
      }
    }
    if (const auto body = r.string("follow")) {
      l.follow = s.body_index(*body);
      if (l.follow < 0) {
        std::vector<std::string_view> known;
        for (const auto& b : s.bodies) known.push_back(b.name);
        r.fail("follow", "unknown body '" + *body + "' (known: " + join(known) + ")");
      }
    }
    r.finish();
    s.grid.levels.push_back(l);
  }
}

/// A body's own particle spacing against the grid (bodies are read before [grid]).
void check_particle_spacing(const Scene& s) {
  const GridSpec& g = s.grid;
  for (const BodySpec& b : s.bodies) {
    if (b.particle_spacing <= 0) continue;
    const std::string at = where(b.spacing_loc.file, b.spacing_loc.line, b.spacing_loc.key);
    const auto mm = [](double v) { return format_mm(v) + " mm"; };
    if (!g.levels.empty())
      throw InputError(at,
                       "a graded grid ([[grid.levels]]) sets each level's spacing from its cells: "
                       "use particles_per_cell");
    // At least a particle per cell along each axis, and at most 16 (the voxeliser's limit).
    const std::string range = "expected a spacing from grid.cell_size / 16 to grid.cell_size (" +
                              mm(g.cell_size / 16) + " to " + mm(g.cell_size) + ")";
    if (b.particle_spacing > g.cell_size * (1 + 1e-9))
      throw InputError(at, range + ": coarser particles leave cells inside the body empty (got " +
                               mm(b.particle_spacing) + ")");
    if (b.particle_spacing < g.cell_size / 16 * (1 - 1e-9))
      throw InputError(at, range + ": finer particles than 16 per cell along an axis (got " +
                               mm(b.particle_spacing) + "; refine the cells instead)");
  }
}

void read_grid(Reader& r, Scene& s) {
  const int n = s.dimension;
  GridSpec& g = s.grid;
  g.loc = r.loc();
  g.cell_size = r.required("cell_size", dim::length, Bound::Positive, "0.76 mm");
  if (auto d = r.table("domain", {"min", "max"})) {
    const std::string ex_min = n == 3 ? "-10 -10 0 mm" : "-10 0 mm";
    const std::string ex_max = n == 3 ? "10 10 27 mm" : "10 27 mm";
    auto lo = d->vector("min", dim::length, n);
    if (!lo) d->missing("min", "the lower corner, e.g. \"" + ex_min + "\"");
    auto hi = d->vector("max", dim::length, n);
    if (!hi) d->missing("max", "the upper corner, e.g. \"" + ex_max + "\"");
    d->finish();
    for (int i = 0; i < n; ++i) {
      if (!((*hi)[i] > (*lo)[i])) {
        const std::string axis(1, "xyz"[i]);
        d->fail("max", "must be above min in every component, but " + axis + ": max " +
                           format_number((*hi)[i]) + " m <= min " + format_number((*lo)[i]) + " m");
      }
    }
    g.domain_given = true;
    g.domain_min = *lo;
    g.domain_max = *hi;
    if (r.get("padding")) {
      r.fail("padding",
             "cannot be combined with grid.domain (padding applies only when the domain is "
             "fitted to the bodies)");
    }
    g.padding = 0;
  } else {
    g.padding = r.quantity("padding", dim::length, Bound::NonNegative).value_or(2 * g.cell_size);
  }
  g.sparse = r.boolean("sparse").value_or(false);
  read_levels(r, s);
  if (g.sparse && !g.levels.empty())
    r.fail("sparse",
           "a graded grid ([[grid.levels]]) keeps its own node list; use one or the other");
  r.finish();
}

void read_boundary(Reader& r, Scene& s) {
  static constexpr std::string_view kFaces[6] = {"x_min", "x_max", "y_min",
                                                 "y_max", "z_min", "z_max"};
  const auto read_type = [&r](std::string_view key) {
    return r.choice<BoundaryType>(key, {{"free", BoundaryType::Free},
                                        {"slip", BoundaryType::Slip},
                                        {"fixed", BoundaryType::Fixed}});
  };
  const BoundaryType all = read_type("all").value_or(BoundaryType::Free);
  for (int f = 0; f < 6; ++f) {
    if (s.dimension == 2 && f >= 4) {
      if (r.get(kFaces[f])) {
        r.fail(kFaces[f], "not available in 2D scenes (the faces are x_min, x_max, y_min, y_max)");
      }
      s.boundary.face[f] = BoundaryType::Free;
      continue;
    }
    s.boundary.face[f] = read_type(kFaces[f]).value_or(all);
  }
  r.finish();
}

void read_implicit(Reader& r, ImplicitSpec& m) {
  m.theta = r.number("theta", Bound::NonNegative).value_or(1.0);
  r.check("theta", m.theta <= 1.0, "must be between 0 (explicit) and 1 (fully implicit)");
  m.formulation = r.choice<Formulation>("formulation", {{"velocity", Formulation::Velocity},
                                                        {"momentum", Formulation::Momentum}})
                      .value_or(Formulation::Momentum);
  const KrylovMethod natural =
      m.formulation == Formulation::Velocity ? KrylovMethod::CG : KrylovMethod::GMRES;
  m.krylov =
      r.choice<KrylovMethod>("krylov", {{"cg", KrylovMethod::CG}, {"gmres", KrylovMethod::GMRES}})
          .value_or(natural);
  if (m.krylov == KrylovMethod::CG && m.formulation == Formulation::Momentum)
    r.fail("krylov",
           "CG needs a symmetric Jacobian, and the momentum formulation's is not (001, section "
           "3.2): use krylov = \"gmres\", or formulation = \"velocity\"");
  m.newton_tolerance = r.number("newton_tolerance", Bound::Positive).value_or(1e-5);
  m.linear_tolerance = r.number("linear_tolerance", Bound::Positive).value_or(1e-3);
  r.check("linear_tolerance", m.linear_tolerance < 1.0, "must be below 1");
  m.derivative_step = r.number("derivative_step", Bound::Positive).value_or(1e-5);
  r.check("derivative_step", m.derivative_step < 1.0, "must be below 1 (the seed uses 1e-5)");
  m.gmres_basis = static_cast<int>(r.integer("gmres_basis", 1, 1000).value_or(20));
  m.gmres_restarts = static_cast<int>(r.integer("gmres_restarts", 0, 1000).value_or(0));
  m.max_krylov = static_cast<int>(r.integer("max_krylov", 1, 100000).value_or(200));
  m.max_newton = static_cast<int>(r.integer("max_newton", 1, 10000).value_or(25));
  m.max_line_search = static_cast<int>(r.integer("max_line_search", 0, 60).value_or(8));
  m.dt_initial_multiple = r.number("dt_initial_multiple", Bound::Positive).value_or(1.0);
  m.dt_target_multiple = r.number("dt_target_multiple", Bound::Positive).value_or(100.0);
  r.check("dt_target_multiple", m.dt_target_multiple >= m.dt_initial_multiple,
          "must be >= dt_initial_multiple (" + format_number(m.dt_initial_multiple) + ")");
  m.ramp = r.number("ramp", Bound::NonNegative).value_or(0.2);
  m.cut = r.number("cut", Bound::Positive).value_or(0.5);
  r.check("cut", m.cut < 1.0, "must be below 1 (the factor on a step that failed)");
  m.max_cuts = static_cast<int>(r.integer("max_cuts", 0, 60).value_or(10));
  m.forcing = r.choice<Forcing>("forcing", {{"fixed", Forcing::Fixed},
                                            {"eisenstat-walker", Forcing::EisenstatWalker}})
                  .value_or(Forcing::EisenstatWalker);
  m.preconditioner =
      r.choice<Preconditioner>("preconditioner", {{"none", Preconditioner::None},
                                                  {"diagonal", Preconditioner::Diagonal},
                                                  {"tangent", Preconditioner::Tangent}})
          .value_or(m.formulation == Formulation::Velocity ? Preconditioner::Tangent
                                                           : Preconditioner::None);
  m.initial_guess = r.choice<InitialGuess>("initial_guess", {{"particles", InitialGuess::Particles},
                                                             {"previous", InitialGuess::Previous}})
                        .value_or(m.formulation == Formulation::Velocity ? InitialGuess::Previous
                                                                         : InitialGuess::Particles);
  r.finish();
}

void read_solver(Reader& r, Scene& s) {
  SolverSpec& v = s.solver;
  v.type = r.choice<SolverType>(
                "type", {{"explicit", SolverType::Explicit}, {"implicit", SolverType::Implicit}})
               .value_or(SolverType::Explicit);
  if (auto t = r.table(
          "implicit", {"theta", "formulation", "krylov", "newton_tolerance", "linear_tolerance",
                       "derivative_step", "gmres_basis", "gmres_restarts", "max_krylov",
                       "max_newton", "max_line_search", "dt_initial_multiple", "dt_target_multiple",
                       "ramp", "cut", "max_cuts", "forcing", "preconditioner", "initial_guess"})) {
    if (v.type != SolverType::Implicit)
      r.fail("implicit", "is used only with solver.type = \"implicit\"");
    read_implicit(*t, v.implicit);
  }
  if (v.type == SolverType::Implicit && r.has("scheme"))
    r.fail("scheme",
           "is for the explicit solver; the implicit one takes solver.implicit.formulation "
           "(\"velocity\" or \"momentum\")");
  v.scheme =
      r.choice<Scheme>("scheme",
                       {{"USF", Scheme::USF}, {"USL", Scheme::USL}, {"MUSL", Scheme::MUSL}}, true)
          .value_or(Scheme::MUSL);
  v.cfl = r.number("cfl", Bound::Positive).value_or(0.5);
  v.end_time = r.required("end_time", dim::time, Bound::Positive, "80 us");
  if (auto t = r.quantity("dt_max", dim::time, Bound::Positive)) v.dt_max = *t;
  if (auto g = r.vector("gravity", dim::acceleration, s.dimension)) v.gravity = *g;
  v.on_exit = r.choice<OnExit>("on_exit", {{"stop", OnExit::Stop}, {"remove", OnExit::Remove}})
                  .value_or(OnExit::Stop);
  v.energy_growth_limit = r.number("energy_growth_limit", Bound::Positive).value_or(0.05);
  v.max_steps = static_cast<long>(r.integer("max_steps", 0).value_or(0));
  if (const toml::node* bv = r.get("bulk_viscosity")) {
    if (const auto* flag = bv->as_boolean()) {
      if (!flag->get()) v.bulk_linear = v.bulk_quadratic = 0;
    } else if (bv->is_table()) {
      auto t = r.table("bulk_viscosity", {"linear", "quadratic"});
      v.bulk_linear = t->number("linear", Bound::NonNegative).value_or(0.06);
      v.bulk_quadratic = t->number("quadratic", Bound::NonNegative).value_or(1.5);
      t->finish();
    } else {
      r.fail("bulk_viscosity",
             "expected a table { linear = 0.06, quadratic = 1.5 }, or false to disable it, " +
                 got(*bv));
    }
  }
  r.finish();
}

void read_output(Reader& r, Scene& s) {
  OutputSpec& o = s.output;
  o.frames = static_cast<int>(r.integer("frames", 1, INT_MAX).value_or(10));
  o.history_interval = r.quantity("history_interval", dim::time, Bound::NonNegative).value_or(0.0);
  if (const toml::node* f = r.get("fields")) {
    const auto* a = f->as_array();
    if (!a) r.fail("fields", "expected an array of strings, e.g. [\"x\", \"v\"], " + got(*f));
    for (std::size_t i = 0; i < a->size(); ++i) {
      const toml::node& e = (*a)[i];
      const auto* str = e.as_string();
      if (!str) {
        r.fail("fields[" + std::to_string(i) + "]", "expected a string, " + got(e), &e);
      }
      o.fields.push_back(str->get());
    }
  }
  o.precision = r.choice<Precision>("precision", {{"float64", Precision::Float64},
                                                  {"float32", Precision::Float32}})
                    .value_or(Precision::Float64);
  r.finish();
}

void read_scene(const Doc& doc, const toml::table& root, Scene& s) {
  Reader top(doc, root, "", Origin{},
             {"scene", "materials", "bodies", "loads", "grid", "boundary", "solver", "output"});
  if (auto t = top.table("scene", {"title", "dimension", "geometry"})) {
    s.title = t->string("title").value_or("");
    if (auto d = t->integer("dimension")) {
      t->check("dimension", *d == 2 || *d == 3, "must be 3, or 2 (the x-y plane)");
      s.dimension = static_cast<int>(*d);
    }
    if (auto g = t->choice<int>("geometry",
                                {{"plane-strain", 0}, {"axisymmetric", 1}, {"plane-stress", 2}})) {
      if (s.dimension != 2)
        t->fail("geometry",
                "is for 2D scenes (dimension = 2): \"plane-strain\", "
                "\"plane-stress\" or \"axisymmetric\"");
      s.axisymmetric = *g == 1;
      s.plane_stress = *g == 2;
    }
    t->finish();
  }

  const toml::node* mats = top.get("materials");
  if (!mats) {
    top.fail("materials",
             "missing required table [materials] (one [materials.<name>] table per "
             "material)");
  }
  const auto* mt = mats->as_table();
  if (!mt)
    top.fail("materials", "expected a table of materials ([materials.<name>]), " + got(*mats));
  if (mt->empty()) top.fail("materials", "at least one material is required ([materials.<name>])");
  const Origin mats_origin = top.origin_of(*mats);
  // toml++ tables are sorted by key, so materials are numbered in alphabetical order; this
  // keeps the numbering unchanged when Scene::toml is parsed again.
  for (auto&& [name, node] : *mt) {
    const std::string path = "materials." + std::string(name.str());
    const Origin o = doc.origin(node, mats_origin);
    const auto* t = node.as_table();
    if (!t) {
      throw InputError(doc.where(o, path), "expected a table ([" + path + "]), " + got(node));
    }
    Reader r(doc, *t, path, o,
             {"density", "youngs_modulus", "poisson_ratio", "strength", "eos", "failure"});
    s.materials.push_back(read_material(r, std::string(name.str())));
  }

  read_bodies(top, s);
  read_loads(top, s);

  {
    Reader g = top.required_table("grid", {"cell_size", "domain", "padding", "sparse", "levels"},
                                  "cell_size is required");
    read_grid(g, s);
  }
  check_particle_spacing(s);
  if (auto b =
          top.table("boundary", {"all", "x_min", "x_max", "y_min", "y_max", "z_min", "z_max"})) {
    read_boundary(*b, s);
  }
  {
    Reader v = top.required_table(
        "solver",
        {"scheme", "cfl", "end_time", "dt_max", "gravity", "on_exit", "energy_growth_limit",
         "max_steps", "bulk_viscosity", "type", "implicit"},
        "end_time is required");
    read_solver(v, s);
  }
  if (auto o = top.table("output", {"frames", "history_interval", "fields", "precision"})) {
    read_output(*o, s);
  }
  if (s.axisymmetric) {
    // x is the radius: the domain starts at the axis or beyond, and the axis holds u_r = 0.
    const SourceLoc& g = s.grid.loc;
    if (!s.grid.domain_given)
      throw InputError(where(g.file, g.line, "grid.domain"),
                       "axisymmetric scenes need grid.domain with min x >= 0 (x is the radius)");
    if (s.grid.domain_min.x() < 0)
      throw InputError(where(g.file, g.line, "grid.domain.min"),
                       "the radius x must be >= 0 in axisymmetric scenes");
    if (s.grid.domain_min.x() == 0 && s.boundary.face[0] == BoundaryType::Free)
      throw InputError(where(g.file, g.line, "boundary.x_min"),
                       "the axis r = 0 is the domain face x_min: set boundary.x_min = \"slip\" "
                       "(no radial velocity on the axis)");
  }
  top.finish();
}

// ---------------------------------------------------------------------------------------------
// --set overrides

std::string trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t");
  return std::string(s.substr(b, e - b + 1));
}

/// Applies one "key=value" override to the document.
void apply_override(toml::table& root, const std::string& arg, Doc& doc) {
  const auto eq = arg.find('=');
  if (eq == std::string::npos) {
    throw InputError("--set " + arg, "expected key=value, e.g. solver.cfl=0.3");
  }
  const std::string key = trim(std::string_view(arg).substr(0, eq));
  if (key.empty()) {
    throw InputError("--set " + arg,
                     "empty key before '=' (expected key=value, e.g. "
                     "solver.cfl=0.3)");
  }
  const std::string loc = "--set " + key;
  const std::string value = trim(std::string_view(arg).substr(eq + 1));
  if (value.empty()) throw InputError(loc, "empty value after '='");

  std::vector<std::string> parts;
  for (std::size_t start = 0;;) {
    const auto dot = key.find('.', start);
    parts.push_back(trim(std::string_view(key).substr(
        start, dot == std::string::npos ? std::string::npos : dot - start)));
    if (parts.back().empty()) {
      throw InputError(loc, "empty part in the key (expected a dotted path, e.g. solver.cfl)");
    }
    if (dot == std::string::npos) break;
    start = dot + 1;
  }

  toml::table* t = &root;
  std::size_t i = 0;
  std::string walked;
  if ((parts[0] == "bodies" || parts[0] == "loads") && parts.size() > 1) {
    const std::string& what = parts[0];
    if (parts.size() < 3) {
      throw InputError(loc, what == "bodies"
                                ? "expected bodies.<name or index>.<key>, e.g. bodies.bar.velocity"
                                : "expected loads.<index>.<key>, e.g. loads.0.force");
    }
    auto* arr = root.get_as<toml::array>(what);
    if (!arr) throw InputError(loc, "the scene has no [[" + what + "]] to change");
    const std::string& sel = parts[1];
    toml::node* body = nullptr;
    if (std::all_of(sel.begin(), sel.end(), [](char c) { return c >= '0' && c <= '9'; })) {
      std::size_t index = 0;
      const auto [ptr, ec] = std::from_chars(sel.data(), sel.data() + sel.size(), index);
      if (ec != std::errc() || index >= arr->size()) {
        throw InputError(loc, "no " + std::string(what == "bodies" ? "body" : "load") +
                                  " with index " + sel + " (the scene has " +
                                  std::to_string(arr->size()) + ", numbered from 0)");
      }
      body = arr->get(index);
    } else if (what == "loads") {
      throw InputError(loc, "loads are selected by index, e.g. loads.0.force");
    } else {
      std::vector<std::string> known;
      for (auto& e : *arr) {
        const auto* bt = e.as_table();
        const auto name = bt ? (*bt)["name"].value<std::string>() : std::nullopt;
        if (!name) continue;
        if (*name == sel) body = &e;
        known.push_back(*name);
      }
      if (!body) {
        std::vector<std::string_view> k(known.begin(), known.end());
        throw InputError(loc, "unknown body '" + sel + "' (known: " + join(k) + ")");
      }
    }
    t = body->as_table();
    if (!t) throw InputError(loc, what + "." + sel + " is not a table");
    i = 2;
    walked = what + "." + sel;
  } else if (parts.size() > 3 && parts[0] == "grid" && parts[1] == "levels") {
    // grid.levels.<index>.<key>
    auto* arr = root["grid"]["levels"].as_array();
    if (!arr) throw InputError(loc, "the scene has no [[grid.levels]] to change");
    const std::string& sel = parts[2];
    std::size_t index = 0;
    const auto [ptr, ec] = std::from_chars(sel.data(), sel.data() + sel.size(), index);
    if (ec != std::errc() || ptr != sel.data() + sel.size() || index >= arr->size())
      throw InputError(loc, "no level box with index " + sel + " (the scene has " +
                                std::to_string(arr->size()) + ", numbered from 0)");
    t = arr->get(index)->as_table();
    if (!t) throw InputError(loc, "grid.levels." + sel + " is not a table");
    i = 3;
    walked = "grid.levels." + sel;
  }
  for (; i + 1 < parts.size(); ++i) {
    walked += (walked.empty() ? "" : ".") + parts[i];
    toml::node* n = t->get(parts[i]);
    if (!n) {
      auto [it, inserted] = t->insert_or_assign(parts[i], toml::table{});
      n = &it->second;
      doc.record(*n, key);
    } else if (!n->is_table()) {
      throw InputError(loc, "'" + walked + "' is " + type_name(*n) + ", not a table");
    }
    t = n->as_table();
  }

  // The value as TOML ("0.3", "\"0.38 mm\"", "[1, 2, 3]", "{ linear = 0 }"), else as a string.
  std::optional<toml::table> parsed;
  try {
    parsed = toml::parse("v = " + value);
  } catch (const toml::parse_error&) {
    parsed.reset();
  }
  toml::node* v = parsed && parsed->size() == 1 ? parsed->get("v") : nullptr;
  auto [it, inserted] =
      v ? t->insert_or_assign(parts.back(), *v) : t->insert_or_assign(parts.back(), value);
  doc.record(it->second, key);
  // A body's particles are set by particles_per_cell or by particle_spacing: setting one
  // replaces the other, so a script can switch a scene's body between them (and the document,
  // which the model carries, stays one a parser accepts).
  if (parts[0] == "bodies" && parts.size() == 3) {
    const auto drop = [&](const char* other) {
      if (const toml::node* n = t->get(other)) doc.set_by.erase(n);
      t->erase(other);
    };
    if (parts[2] == "particle_spacing") drop("particles_per_cell");
    if (parts[2] == "particles_per_cell") drop("particle_spacing");
  }
}

/// True when every float in the document is exact with 6 significant digits; then the
/// formatter may print floats briefly ("0.35", not "0.34999999999999998") without loss.
bool floats_are_short(const toml::node& n) {
  if (const auto* f = n.as_floating_point()) {
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, f->get(), std::chars_format::general, 6);
    double back = 0;
    const auto [ptr, ec] = std::from_chars(buf, r.ptr, back);
    return ec == std::errc() && back == f->get();
  }
  if (const auto* t = n.as_table()) {
    for (auto&& [k, v] : *t) {
      if (!floats_are_short(v)) return false;
    }
  } else if (const auto* a = n.as_array()) {
    for (const auto& e : *a) {
      if (!floats_are_short(e)) return false;
    }
  }
  return true;
}

/// The document as TOML text; parsing it again gives the same document.
std::string to_toml(const toml::table& root) {
  auto flags = toml::toml_formatter::default_flags;
  if (floats_are_short(root)) flags |= toml::format_flags::relaxed_float_precision;
  std::ostringstream text;
  text << toml::toml_formatter(root, flags);
  std::string s = text.str();
  if (!s.empty() && s.back() != '\n') s += '\n';
  return s;
}

}  // namespace

int Scene::body_index(const std::string& name) const {
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

double Scene::measure_factor() const {
  return axisymmetric ? 2.0 * 3.14159265358979323846 : 1.0;
}

int Scene::material_index(const std::string& name) const {
  for (std::size_t i = 0; i < materials.size(); ++i) {
    if (materials[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

Scene parse_scene(const std::string& toml_text, const std::string& source,
                  const std::string& directory, const std::vector<std::string>& overrides) {
  Doc doc;
  doc.file = source;
  toml::table root;
  try {
    root = toml::parse(toml_text, source);
  } catch (const toml::parse_error& e) {
    const auto& b = e.source().begin;
    throw InputError(where(source, static_cast<int>(b.line), ""),
                     "TOML syntax error: " + std::string(e.description()) +
                         (b.column > 0 ? " (column " + std::to_string(b.column) + ")" : ""));
  }
  for (const auto& o : overrides) apply_override(root, o, doc);

  Scene s;
  s.source = source;
  s.directory = directory;
  read_scene(doc, root, s);
  s.toml = to_toml(root);
  return s;
}

Scene load_scene(const std::string& path, const std::vector<std::string>& overrides) {
  if (path == "-") {
    std::ostringstream text;
    text << std::cin.rdbuf();
    if (std::cin.bad()) throw InputError("<stdin>", "cannot read the scene from standard input");
    return parse_scene(text.str(), "<stdin>", "", overrides);
  }
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw InputError(path, "cannot read the scene file: it is a directory");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw InputError(path, "cannot read the scene file: " +
                               std::error_code(errno, std::generic_category()).message());
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(path, "cannot read the scene file: read error");
  return parse_scene(text.str(), path, std::filesystem::path(path).parent_path().string(),
                     overrides);
}

}  // namespace mpm
