// Scene file parser: TOML (toml++) -> Scene. Reference for users: docs/scene.md.
//
// The file is parsed by toml++, the --set overrides are applied to the document
// (overrides.cpp), and its tables are read in order, each through a Reader that knows the keys
// the table accepts (toml_reader.hpp): materials (read_materials.cpp), bodies and loads
// (read_bodies.cpp), grid and boundary (read_grid.cpp), solver and output (read_solver.cpp).
#include "mpm/scene/scene.hpp"

#include <toml++/toml.h>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <system_error>

#include "mpm/core/error.hpp"
#include "mpm/core/units.hpp"
#include "mpm/scene/overrides.hpp"
#include "mpm/scene/read_sections.hpp"
#include "mpm/scene/toml_reader.hpp"

namespace mpm {
namespace {

using namespace scene_toml;

/// [scene]: title, dimension and the 2D geometry.
void read_scene_table(Reader& top, Scene& s) {
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
}

/// Axisymmetric scenes: x is the radius, so the domain starts at the axis or beyond, and the
/// axis holds u_r = 0.
void check_axisymmetric(const Scene& s) {
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

/// HJC's damage_length (docs/scene.md) is at least the finest cell: shorter, each particle's
/// increment would stay in its own cell (the damage local) while its lattice grew as
/// (extent / l)^D nodes.
void check_damage_length(const Scene& s) {
  const double finest = s.grid.cell_size / double(1 << (s.grid.level_count() - 1));
  for (const MaterialSpec& m : s.materials) {
    const HjcSpec& h = m.hjc;
    if (m.strength.model != StrengthModel::Hjc || h.damage_length <= 0) continue;
    if (h.damage_length < finest * (1 - 1e-9))
      throw InputError(
          where(h.damage_length_loc.file, h.damage_length_loc.line, h.damage_length_loc.key),
          "expected at least the finest cell, " + format_mm(finest) +
              " mm (a few cells for the average to act), got " + format_mm(h.damage_length) +
              " mm");
  }
}

void read_scene(const Doc& doc, const toml::table& root, Scene& s) {
  Reader top(doc, root, "", Origin{},
             {"scene", "materials", "bodies", "loads", "contact", "grid", "boundary", "solver",
              "output", "rebar"});
  read_scene_table(top, s);
  read_materials(top, s);
  read_bodies(top, s);
  read_loads(top, s);
  read_contacts(top, s);
  read_rebars(top, s);

  {
    Reader g =
        top.required_table("grid", {"cell_size", "domain", "padding", "sparse", "levels", "shape"},
                           "cell_size is required");
    read_grid(g, s);
  }
  check_particle_spacing(s);
  check_damage_length(s);
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
  if (auto o = top.table("output", {"frames", "history_interval", "fields", "precision",
                                    "checkpoint", "body_history"})) {
    read_output(*o, s);
  }
  if (s.axisymmetric) check_axisymmetric(s);
  if (!s.contacts.empty() && s.solver.type == SolverType::Implicit) {
    const SourceLoc& c = s.contacts.front().loc;
    throw InputError(where(c.file, c.line, c.key),
                     "contact between bodies needs the explicit solver (solver.type = "
                     "\"explicit\"); the implicit solver has one velocity field");
  }
  if (s.solver.type == SolverType::Implicit)
    for (const MaterialSpec& m : s.materials)
      if (m.strength.model == StrengthModel::Hjc)
        throw InputError(where(m.loc.file, m.loc.line, m.loc.key),
                         "HJC concrete needs the explicit solver (solver.type = \"explicit\")");
  if (!s.rebars.empty() && (s.dimension != 3 || s.solver.type == SolverType::Implicit)) {
    const SourceLoc& c = s.rebars.front().loc;
    throw InputError(where(c.file, c.line, c.key),
                     "rebar needs a 3D scene and the explicit solver (truss elements in "
                     "3D, 004 section 2)");
  }
  top.finish();
}

}  // namespace

const std::vector<std::string>& field_variables() {
  static const std::vector<std::string> names = {"x",     "y",     "z",     "r",     "x_min",
                                                 "x_max", "y_min", "y_max", "z_min", "z_max"};
  return names;
}

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
