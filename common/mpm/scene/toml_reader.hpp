#pragma once
/// Private to the scene parser (scene/*.cpp): the TOML reader with locations and units.
///
/// Every table is read through a Reader that knows the keys the table accepts (anything else is
/// reported as an unknown key), converts values to typed SI values and produces error messages
/// that name the file, the line and the dotted key. To add a key: add its name to the key list
/// of its table and read it where the table is read; Reader::finish() catches a listed key that
/// is never read.
#include <toml++/toml.h>

#include <cctype>
#include <climits>
#include <cstddef>
#include <initializer_list>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "mpm/core/types.hpp"
#include "mpm/core/units.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm::scene_toml {

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
  std::string where(const Origin& o, const std::string& path) const;
  /// Origin of a node found inside a table whose origin is `parent`.
  Origin origin(const toml::node& n, const Origin& parent) const;
  /// Marks a node and everything below it as coming from the override `key`.
  void record(const toml::node& n, const std::string& key);
};

/// "a string", "an integer", ... for messages.
std::string type_name(const toml::node& n);
/// The shortest text that reads back as v ("0.35", "1e-05").
std::string format_number(double v);
/// The value as the user wrote it, for messages: strings quoted, numbers as numbers.
std::string show(const toml::node& n);
/// "got 3 (an integer)", "got a table".
std::string got(const toml::node& n);
/// The items joined by `sep`.
std::string join(const std::vector<std::string_view>& items, std::string_view sep = ", ");

/// Reads one TOML table: checks for unknown keys, converts values, reports mistakes.
class Reader {
 public:
  /// `keys` are all the keys the table accepts; any other key is an error right away.
  Reader(const Doc& doc, const toml::table& table, std::string path, Origin origin,
         std::vector<std::string_view> keys);

  const std::string& path() const { return path_; }
  const Origin& origin() const { return origin_; }
  const Doc& doc() const { return *doc_; }
  const toml::table& table() const { return *table_; }

  /// Dotted path of a key of this table.
  std::string key_path(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
  }

  /// Where the table is, as a SourceLoc for the structs.
  SourceLoc loc() const;
  /// Where a key's value is (its line, or the --set that gave it), as a SourceLoc for the
  /// structs; mpm::where(loc.file, loc.line, loc.key) names it as Doc::where does.
  SourceLoc loc_of(std::string_view key) const;

  /// The key's value, or nullptr. Marks the key as read.
  const toml::node* get(std::string_view key);

  bool has(std::string_view key) const { return table_->contains(key); }

  /// Origin of a node inside this table.
  Origin origin_of(const toml::node& n) const { return doc_->origin(n, origin_); }

  /// Fails at a key: at its value when present (or at `node`), else at the table.
  [[noreturn]] void fail(std::string_view key, const std::string& message,
                         const toml::node* node = nullptr) const;
  /// Fails at the table itself.
  [[noreturn]] void fail_table(const std::string& message) const;
  /// "missing required key 'density' (a density, e.g. "8930 kg/m^3")".
  [[noreturn]] void missing(std::string_view key, const std::string& what) const;
  /// Fails with `message` + ", got <value>" unless `ok`.
  void check(std::string_view key, bool ok, const std::string& message) const;
  /// Rejects keys that the chosen model or shape does not use.
  void reject(std::initializer_list<std::string_view> keys, const std::string& why);

  /// A scalar value in SI (or degrees when `angle`): a number, or a string with a unit.
  double scalar(const toml::node& n, std::string_view key, const Dimension& d, bool angle) const;
  /// Fails unless v is on the side of zero `b` asks for ("every component " + rule, ...).
  void check_bound(std::string_view key, double v, Bound b, const toml::node& n,
                   std::string_view every = "") const;

  /// A quantity in SI, nullopt when absent. A plain number is taken as SI.
  std::optional<double> quantity(std::string_view key, const Dimension& d, Bound b = Bound::Any);
  /// A dimensionless number.
  std::optional<double> number(std::string_view key, Bound b = Bound::Any) {
    return quantity(key, dim::none, b);
  }
  /// An angle in degrees: a number (degrees) or "30 deg", "0.5 rad".
  std::optional<double> angle(std::string_view key);
  /// A required quantity; `example` is shown when it is missing ("8930 kg/m^3").
  double required(std::string_view key, const Dimension& d, Bound b, std::string_view example,
                  std::string_view note = "");
  /// An integer in [lo, hi].
  std::optional<long long> integer(std::string_view key, long long lo = LLONG_MIN,
                                   long long hi = LLONG_MAX);
  std::optional<std::string> string(std::string_view key);
  std::optional<bool> boolean(std::string_view key);

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
                             bool angle = false, bool broadcast = false);

  /// A sub-table, nullopt when absent.
  std::optional<Reader> table(std::string_view key, std::vector<std::string_view> keys);
  /// A required sub-table.
  Reader required_table(std::string_view key, std::vector<std::string_view> keys,
                        std::string_view note);

  /// Checks that every accepted key present was read (a parser bug otherwise).
  void finish() const;

 private:
  const Doc* doc_;
  const toml::table* table_;
  std::string path_;
  Origin origin_;
  std::vector<std::string_view> keys_;
  std::set<std::string> read_;
};

}  // namespace mpm::scene_toml
