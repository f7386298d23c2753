// The scene parser's [[bodies]] (shape, placement, particles, rigid contact) and [[loads]].
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>
#include <vector>

#include "mpm/core/error.hpp"
#include "mpm/core/expression.hpp"
#include "mpm/scene/read_sections.hpp"

namespace mpm::scene_toml {

namespace {

using namespace std::string_literals;

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
                                                 "diameter",
                                                 "crh",
                                                 "file",
                                                 "scale",
                                                 "rotate",
                                                 "translate",
                                                 "velocity",
                                                 "particles_per_cell",
                                                 "particle_spacing",
                                                 "rigid",
                                                 "slip",
                                                 "angular_velocity",
                                                 "spin_centre",
                                                 "velocity_field",
                                                 "stress_field",
                                                 "cut_by_domain"};

/// The body's material, or none for a rigid body.
void read_body_material(Reader& r, const Scene& scene, BodySpec& b) {
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
}

/// The body's shape and the keys that size it (and no key of another shape).
void read_shape(Reader& r, const Scene& scene, BodySpec& b) {
  const int n = scene.dimension;
  const bool two_d = n == 2;
  const auto shape = r.choice<ShapeKind>("shape", {{"box", ShapeKind::Box},
                                                   {"cylinder", ShapeKind::Cylinder},
                                                   {"sphere", ShapeKind::Sphere},
                                                   {"ogive", ShapeKind::Ogive},
                                                   {"mesh", ShapeKind::Mesh}});
  if (!shape) r.missing("shape", "one of \"box\", \"cylinder\", \"sphere\", \"ogive\", \"mesh\"");
  b.shape = *shape;
  if (two_d && b.shape != ShapeKind::Box && b.shape != ShapeKind::Sphere &&
      b.shape != ShapeKind::Ogive) {
    r.fail("shape", "shape \"" + *r.string("shape") +
                        "\" is not available in 2D scenes; use box, sphere (a disk) or ogive "
                        "(its axial section)");
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
      r.reject({"length"}, not_for("cylinder and ogive"));
      r.reject({"file"}, not_for("mesh"));
      break;
    case ShapeKind::Cylinder:
      b.radius = r.required("radius", dim::length, Bound::Positive, "3.8 mm");
      b.length = r.required("length", dim::length, Bound::Positive, "25.4 mm");
      r.reject({"size"}, not_for("box"));
      r.reject({"file"}, not_for("mesh"));
      break;
    case ShapeKind::Ogive:
      b.radius = 0.5 * r.required("diameter", dim::length, Bound::Positive, "12.9 mm",
                                  "the shank's diameter");
      b.length = r.required("length", dim::length, Bound::Positive, "88.9 mm",
                            "overall, from the base to the nose tip");
      b.crh = r.required("crh", dim::none, Bound::Positive, "3.0",
                         "the nose's arc radius in shank diameters, at least 0.5");
      r.reject({"size"}, not_for("box"));
      r.reject({"radius"}, not_for("cylinder and sphere"));
      r.reject({"file"}, not_for("mesh"));
      break;
    case ShapeKind::Sphere:
      b.radius = r.required("radius", dim::length, Bound::Positive, "3.8 mm");
      r.reject({"size"}, not_for("box"));
      r.reject({"length"}, not_for("cylinder and ogive"));
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
      r.reject({"length"}, not_for("cylinder and ogive"));
      break;
    }
  }
  if (b.shape != ShapeKind::Ogive) r.reject({"diameter", "crh"}, not_for("ogive"));
}

/// Scale, rotation, translation and velocity.
void read_placement(Reader& r, int n, BodySpec& b) {
  const bool two_d = n == 2;
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
}

/// particles_per_cell, or particle_spacing.
void read_particles(Reader& r, BodySpec& b) {
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
}

/// slip: for rigid bodies only.
void read_slip(Reader& r, int n, BodySpec& b) {
  const bool two_d = n == 2;
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
}

/// One formula of a field: a string (or a plain number) that compiles over field_variables();
/// `sub` is "[1]" or ".xy", the component after the key.
FieldExpression read_formula(Reader& r, std::string_view key, const std::string& sub,
                             const toml::node& n) {
  std::string text;
  if (const auto* str = n.as_string())
    text = str->get();
  else if (n.is_integer() || n.is_floating_point())
    text = format_number(n.value<double>().value());
  else
    r.fail(key,
           "expected a formula of x, y, z, r as a string, e.g. \"0.5*cos(pi*x/0.1)\", " + got(n),
           &n);
  std::vector<double> values(field_variables().size(), 0.0);
  try {
    const Expression compiled(text, field_variables(), values.data());
  } catch (const ExpressionError& e) {
    r.fail(std::string(key) + sub,
           describe(e, text) + " (variables: x y z r x_min x_max y_min y_max z_min z_max, in m)",
           &n);
  }
  SourceLoc loc = r.loc_of(key);
  loc.key += sub;
  return {text, loc};
}

/// angular_velocity, spin_centre, velocity_field, stress_field (not for rigid bodies).
void read_initial_fields(Reader& r, const Scene& scene, BodySpec& b) {
  const int n = scene.dimension;
  for (std::string_view key : {"angular_velocity", "spin_centre", "velocity_field", "stress_field"})
    if (b.rigid && r.has(key))
      r.fail(key, "a rigid body moves at its velocity for ever; it takes no spin or field");
  if (const toml::node* w = r.get("angular_velocity")) {
    if (w->is_string() && w->as_string()->get().find("Hz") != std::string::npos)
      r.fail("angular_velocity",
             "give the angular velocity in rad/s (or 1/s), not Hz (revolutions per second "
             "are 2 pi rad/s), got " +
                 show(*w));
    if (scene.axisymmetric)
      r.fail("angular_velocity",
             "an axisymmetric scene cannot spin a body in its plane (x is the radius)");
    if (n == 2)
      b.angular_velocity = Vec3(0, 0, *r.quantity("angular_velocity", dim::rate));
    else
      b.angular_velocity = *r.vector("angular_velocity", dim::rate, 3);
  }
  if (auto c = r.vector("spin_centre", dim::length, n)) {
    if (!r.has("angular_velocity"))
      r.fail("spin_centre", "a spin centre needs an angular_velocity");
    b.spin_centre = *c;
    b.spin_centre_given = true;
  }
  if (const toml::node* f = r.get("velocity_field")) {
    const auto* arr = f->as_array();
    if (!arr || int(arr->size()) != n)
      r.fail("velocity_field", "expected " + std::to_string(n) +
                                   " formulas (one per axis, in m/s), e.g. [\"0.5*cos(pi*x/0.1)\"" +
                                   (n == 3 ? ", 0, 0]" : ", 0]") + ", " + got(*f));
    for (int a = 0; a < n; ++a)
      b.velocity_field.push_back(
          read_formula(r, "velocity_field", "[" + std::to_string(a) + "]", *arr->get(a)));
  }
  const std::vector<std::string_view> components =
      n == 3 ? std::vector<std::string_view>{"xx", "yy", "zz", "yz", "xz", "xy"}
             : std::vector<std::string_view>{"xx", "yy", "zz", "xy"};
  if (auto t = r.table("stress_field", components)) {
    if (scene.plane_stress && t->has("zz")) t->fail("zz", "a plane-stress sheet has sigma_zz = 0");
    static const char* voigt[6] = {"xx", "yy", "zz", "yz", "xz", "xy"};
    for (const char* c : voigt) {
      const bool in_plane = std::find(components.begin(), components.end(), c) != components.end();
      const toml::node* v = in_plane ? t->get(c) : nullptr;
      b.stress_field.push_back(v ? read_formula(r, "stress_field", "." + std::string(c), *v)
                                 : FieldExpression{"0", r.loc_of("stress_field")});
    }
    t->finish();
  }
}

/// One [[bodies]] table.
BodySpec read_body(Reader& r, const Scene& scene) {
  BodySpec b;
  b.name = *r.string("name");
  b.loc = r.loc();
  read_body_material(r, scene, b);
  read_shape(r, scene, b);
  read_placement(r, scene.dimension, b);
  read_particles(r, b);
  read_slip(r, scene.dimension, b);
  read_initial_fields(r, scene, b);
  b.cut_by_domain = r.boolean("cut_by_domain").value_or(false);
  r.finish();
  return b;
}

}  // namespace

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

}  // namespace mpm::scene_toml

namespace mpm::scene_toml {

namespace {

/// The two body names of a [[contact]] table, as body indices (unknown, rigid or repeated
/// bodies are errors).
std::pair<int, int> read_contact_bodies(Reader& r, const Scene& s) {
  const toml::node* node = r.get("bodies");
  const std::string expected = "two body names, e.g. [\"projectile\", \"plate\"]";
  if (!node) r.missing("bodies", expected);
  const auto* arr = node->as_array();
  if (!arr || arr->size() != 2 || !(*arr)[0].is_string() || !(*arr)[1].is_string())
    r.fail("bodies", "expected " + expected + ", " + got(*node));
  int index[2];
  for (int k = 0; k < 2; ++k) {
    const std::string name = (*arr)[std::size_t(k)].as_string()->get();
    index[k] = s.body_index(name);
    if (index[k] < 0) {
      std::vector<std::string_view> known;
      for (const auto& b : s.bodies) known.push_back(b.name);
      r.fail("bodies", "unknown body '" + name + "' (known: " + join(known) + ")");
    }
    if (s.bodies[index[k]].rigid)
      r.fail("bodies", "body '" + name +
                           "' is rigid: rigid bodies hold the nodes they touch (their contact is "
                           "set by the body's `slip` key), they take no part in [[contact]]");
  }
  if (index[0] == index[1])
    r.fail("bodies", "a body cannot be in contact with itself ('" + s.bodies[index[0]].name +
                         "' is named twice)");
  return {index[0], index[1]};
}

}  // namespace

void read_contacts(Reader& top, Scene& s) {
  const toml::node* node = top.get("contact");
  if (!node) return;
  const auto* arr = node->as_array();
  if (!arr)
    top.fail("contact",
             "expected an array of tables ([[contact]], note the double brackets), " + got(*node));
  const Doc& doc = top.doc();
  const Origin array_origin = top.origin_of(*node);
  for (std::size_t i = 0; i < arr->size(); ++i) {
    const toml::node& e = (*arr)[i];
    const std::string path = "contact." + std::to_string(i);
    const Origin o = doc.origin(e, array_origin);
    const auto* t = e.as_table();
    if (!t) throw InputError(doc.where(o, path), "expected a table ([[contact]]), " + got(e));
    Reader r(doc, *t, path, o, {"bodies", "friction", "normal", "gap", "separation"});
    ContactSpec c;
    c.loc = r.loc();
    std::tie(c.body_a, c.body_b) = read_contact_bodies(r, s);
    c.friction = r.number("friction", Bound::NonNegative).value_or(0.0);
    c.gap = r.number("gap", Bound::Positive).value_or(c.gap);
    if (r.has("separation")) {
      if (r.has("gap"))
        r.fail("separation",
               "expected `gap` (mass centres) or `separation` (surfaces), not both: they are two "
               "ways of deciding where the bodies touch (to try `separation` on a scene that "
               "sets `gap`, take the `gap` line out)");
      c.separation = *r.number("separation", Bound::NonNegative);
    }
    if (const auto normal = r.string("normal")) {
      const std::string &a = s.bodies[c.body_a].name, &b = s.bodies[c.body_b].name;
      if (*normal == "steeper")
        c.normal = ContactSpec::Normal::Steeper;
      else if (*normal == "average")
        c.normal = ContactSpec::Normal::Average;
      else if (*normal == a)
        c.normal = ContactSpec::Normal::BodyA;
      else if (*normal == b)
        c.normal = ContactSpec::Normal::BodyB;
      else
        r.fail("normal", "expected \"steeper\", \"average\" or one body of the pair ('" + a +
                             "' or '" + b + "'), got '" + *normal + "'");
    }
    for (const auto& other : s.contacts)
      if (std::minmax(other.body_a, other.body_b) == std::minmax(c.body_a, c.body_b))
        r.fail("bodies", "the pair '" + s.bodies[c.body_a].name + "', '" + s.bodies[c.body_b].name +
                             "' is already in contact (" +
                             where(other.loc.file, other.loc.line, other.loc.key) + ")");
    r.finish();
    s.contacts.push_back(c);
  }
}

}  // namespace mpm::scene_toml
