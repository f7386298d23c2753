// The scene parser's TOML reader: locations, unit conversion and messages (toml_reader.hpp).
#include "mpm/scene/toml_reader.hpp"

#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <system_error>

#include "mpm/core/error.hpp"

namespace mpm::scene_toml {

using namespace std::string_literals;

std::string Doc::where(const Origin& o, const std::string& path) const {
  if (!o.set.empty()) return mpm::where("--set " + o.set, 0, o.set == path ? "" : path);
  return mpm::where(file, o.line, path);
}

Origin Doc::origin(const toml::node& n, const Origin& parent) const {
  if (auto it = set_by.find(&n); it != set_by.end()) return {it->second, 0};
  if (!parent.set.empty()) return parent;  // inside a table that an override created
  const int line = static_cast<int>(n.source().begin.line);
  return {"", line > 0 ? line : parent.line};
}

void Doc::record(const toml::node& n, const std::string& key) {
  set_by[&n] = key;
  if (const auto* t = n.as_table()) {
    for (auto&& [k, v] : *t) record(v, key);
  } else if (const auto* a = n.as_array()) {
    for (const auto& e : *a) record(e, key);
  }
}

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

std::string join(const std::vector<std::string_view>& items, std::string_view sep) {
  std::string s;
  for (const auto& i : items) {
    if (!s.empty()) s += sep;
    s += i;
  }
  return s;
}

/// Reads one TOML table: checks for unknown keys, converts values, reports mistakes.

namespace {

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

}  // namespace

Reader::Reader(const Doc& doc, const toml::table& table, std::string path, Origin origin,
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

SourceLoc Reader::loc() const {
  if (!origin_.set.empty()) return {"--set " + origin_.set, 0, path_};
  return {doc_->file, origin_.line, path_};
}

SourceLoc Reader::loc_of(std::string_view key) const {
  const toml::node* n = table_->get(key);
  const Origin o = n ? origin_of(*n) : origin_;
  const std::string path = key_path(key);
  if (!o.set.empty()) return {"--set " + o.set, 0, o.set == path ? "" : path};
  return {doc_->file, o.line, path};
}

const toml::node* Reader::get(std::string_view key) {
  if (std::find(keys_.begin(), keys_.end(), key) == keys_.end()) {
    throw std::logic_error("scene parser reads key '" + key_path(key) +
                           "' that is not in its key list");
  }
  read_.insert(std::string(key));
  return table_->get(key);
}

void Reader::fail(std::string_view key, const std::string& message, const toml::node* node) const {
  if (!node) node = table_->get(key);
  const Origin o = node ? origin_of(*node) : origin_;
  throw InputError(doc_->where(o, key_path(key)), message);
}

void Reader::fail_table(const std::string& message) const {
  throw InputError(doc_->where(origin_, path_), message);
}

void Reader::missing(std::string_view key, const std::string& what) const {
  fail_table("missing required key '" + std::string(key) + "' (" + what + ")");
}

void Reader::check(std::string_view key, bool ok, const std::string& message) const {
  if (ok) return;
  const toml::node* n = table_->get(key);
  fail(key, n ? message + ", got " + show(*n) : message);
}

void Reader::reject(std::initializer_list<std::string_view> keys, const std::string& why) {
  for (auto key : keys) {
    if (get(key)) fail(key, "not used " + why);
  }
}

double Reader::scalar(const toml::node& n, std::string_view key, const Dimension& d,
                      bool angle) const {
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

void Reader::check_bound(std::string_view key, double v, Bound b, const toml::node& n,
                         std::string_view every) const {
  const char* rule = nullptr;
  if (b == Bound::Positive && !(v > 0)) rule = "must be > 0";
  if (b == Bound::NonNegative && !(v >= 0)) rule = "must be >= 0";
  if (b == Bound::Negative && !(v < 0)) rule = "must be < 0";
  if (rule) fail(key, std::string(every) + rule + ", got " + show(n), &n);
}

std::optional<double> Reader::quantity(std::string_view key, const Dimension& d, Bound b) {
  const toml::node* n = get(key);
  if (!n) return std::nullopt;
  const double v = scalar(*n, key, d, false);
  check_bound(key, v, b, *n);
  return v;
}

std::optional<double> Reader::angle(std::string_view key) {
  const toml::node* n = get(key);
  if (!n) return std::nullopt;
  return scalar(*n, key, dim::none, true);
}

double Reader::required(std::string_view key, const Dimension& d, Bound b, std::string_view example,
                        std::string_view note) {
  if (auto v = quantity(key, d, b)) return *v;
  const std::string ex(example);
  missing(key, (d == dim::none ? "a number"s : dim_name(d)) + ", e.g. " +
                   (d == dim::none ? ex : "\"" + ex + "\"") +
                   (note.empty() ? "" : "; " + std::string(note)));
}

std::optional<long long> Reader::integer(std::string_view key, long long lo, long long hi) {
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

std::optional<std::string> Reader::string(std::string_view key) {
  const toml::node* n = get(key);
  if (!n) return std::nullopt;
  const auto* s = n->as_string();
  if (!s) fail(key, "expected a string, " + got(*n));
  return s->get();
}

std::optional<bool> Reader::boolean(std::string_view key) {
  const toml::node* n = get(key);
  if (!n) return std::nullopt;
  const auto* b = n->as_boolean();
  if (!b) fail(key, "expected true or false, " + got(*n));
  return b->get();
}

std::optional<Vec3> Reader::vector(std::string_view key, const Dimension& d, int n, Bound b,
                                   bool angle, bool broadcast) {
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
      comps.push_back(scalar((*a)[i], std::string(key) + "[" + std::to_string(i) + "]", d, angle));
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

std::optional<Reader> Reader::table(std::string_view key, std::vector<std::string_view> keys) {
  const toml::node* n = get(key);
  if (!n) return std::nullopt;
  const auto* t = n->as_table();
  if (!t) fail(key, "expected a table, " + got(*n));
  return Reader(*doc_, *t, key_path(key), origin_of(*n), std::move(keys));
}

Reader Reader::required_table(std::string_view key, std::vector<std::string_view> keys,
                              std::string_view note) {
  if (auto r = table(key, std::move(keys))) return std::move(*r);
  fail(key, "missing required table [" + key_path(key) + "] (" + std::string(note) + ")");
}

void Reader::finish() const {
  for (auto&& [k, v] : *table_) {
    if (!read_.count(std::string(k.str()))) {
      throw std::logic_error("scene parser accepted but did not read '" + key_path(k.str()) + "'");
    }
  }
}

}  // namespace mpm::scene_toml
