// The scene parser's --set overrides: "key=value" applied to the TOML document before it is
// read (a body by name or index, a load or a level box by index), and the document as text.
#include "mpm/scene/overrides.hpp"

#include <algorithm>
#include <charconv>
#include <optional>
#include <sstream>
#include <string_view>
#include <system_error>
#include <vector>

#include "mpm/core/error.hpp"

namespace mpm::scene_toml {

namespace {

std::string trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t");
  return std::string(s.substr(b, e - b + 1));
}

/// The dotted parts of an override's key: "solver.cfl" -> {"solver", "cfl"}.
std::vector<std::string> key_parts(const std::string& key, const std::string& loc) {
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
  return parts;
}

/// The arrays of tables whose entries --set selects: by index, bodies also by name; what one
/// entry is called in messages, and a key for their examples.
struct Selectable {
  const char* array;
  const char* one;
  const char* example_key;
};
constexpr Selectable kSelectable[] = {{"bodies", "body", "velocity"},
                                      {"loads", "load", "force"},
                                      {"contact", "pair", "friction"},
                                      {"rebar", "[[rebar]] entry", "diameter"}};

/// The entry of kSelectable for an override's first part, or nullptr.
const Selectable* selectable(const std::string& what) {
  for (const Selectable& s : kSelectable)
    if (what == s.array) return &s;
  return nullptr;
}

/// The table of bodies.<name or index>, or of loads, contact or rebar .<index> (parts[0] is
/// one of kSelectable's arrays).
toml::table* select_body_or_load(toml::table& root, const std::vector<std::string>& parts,
                                 const std::string& loc) {
  const std::string& what = parts[0];
  const Selectable& sel_of = *selectable(what);
  const std::string example = what + ".0." + sel_of.example_key;
  if (parts.size() < 3) {
    throw InputError(loc, what == "bodies"
                              ? "expected bodies.<name or index>.<key>, e.g. bodies.bar.velocity"
                              : "expected " + what + ".<index>.<key>, e.g. " + example);
  }
  auto* arr = root.get_as<toml::array>(what);
  if (!arr) throw InputError(loc, "the scene has no [[" + what + "]] to change");
  const std::string& sel = parts[1];
  toml::node* body = nullptr;
  if (std::all_of(sel.begin(), sel.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    std::size_t index = 0;
    const auto [ptr, ec] = std::from_chars(sel.data(), sel.data() + sel.size(), index);
    if (ec != std::errc() || index >= arr->size()) {
      throw InputError(loc, "no " + std::string(sel_of.one) + " with index " + sel +
                                " (the scene has " + std::to_string(arr->size()) +
                                ", numbered from 0)");
    }
    body = arr->get(index);
  } else if (what != "bodies") {
    throw InputError(loc, what + " entries are selected by index, e.g. " + example);
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
  toml::table* t = body->as_table();
  if (!t) throw InputError(loc, what + "." + sel + " is not a table");
  return t;
}

/// The table of grid.levels.<index> (parts[2] is the index).
toml::table* select_level(toml::table& root, const std::vector<std::string>& parts,
                          const std::string& loc) {
  auto* arr = root["grid"]["levels"].as_array();
  if (!arr) throw InputError(loc, "the scene has no [[grid.levels]] to change");
  const std::string& sel = parts[2];
  std::size_t index = 0;
  const auto [ptr, ec] = std::from_chars(sel.data(), sel.data() + sel.size(), index);
  if (ec != std::errc() || ptr != sel.data() + sel.size() || index >= arr->size())
    throw InputError(loc, "no level box with index " + sel + " (the scene has " +
                              std::to_string(arr->size()) + ", numbered from 0)");
  toml::table* t = arr->get(index)->as_table();
  if (!t) throw InputError(loc, "grid.levels." + sel + " is not a table");
  return t;
}

/// The table that holds the key's last part: from the root, or from the selected entry of
/// [[bodies]], [[loads]], [[contact]], [[rebar]] or [[grid.levels]], through the tables of the path
/// (created when missing, as coming from the override `key`).
toml::table* holder(toml::table& root, const std::vector<std::string>& parts,
                    const std::string& key, const std::string& loc, Doc& doc) {
  toml::table* t = &root;
  std::size_t i = 0;
  std::string walked;
  if (selectable(parts[0]) && parts.size() > 1) {
    t = select_body_or_load(root, parts, loc);
    i = 2;
    walked = parts[0] + "." + parts[1];
  } else if (parts.size() > 3 && parts[0] == "grid" && parts[1] == "levels") {
    // grid.levels.<index>.<key>
    t = select_level(root, parts, loc);
    i = 3;
    walked = "grid.levels." + parts[2];
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
  return t;
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

}  // namespace

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
  const std::vector<std::string> parts = key_parts(key, loc);
  toml::table* t = holder(root, parts, key, loc, doc);

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

std::string to_toml(const toml::table& root) {
  auto flags = toml::toml_formatter::default_flags;
  if (floats_are_short(root)) flags |= toml::format_flags::relaxed_float_precision;
  std::ostringstream text;
  text << toml::toml_formatter(root, flags);
  std::string s = text.str();
  if (!s.empty() && s.back() != '\n') s += '\n';
  return s;
}

}  // namespace mpm::scene_toml
