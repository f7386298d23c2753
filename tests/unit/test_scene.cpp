// Scene parser: valid scenes, every kind of mistake (file, line and key in the message),
// --set overrides and the TOML round trip of Scene::toml.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "mpm/core/error.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm {
namespace {

std::string data(const std::string& name) {
  return std::string(MPM_TEST_DATA) + "/scenes/" + name;
}

/// Relative comparison for SI values spanning many decades.
void expect_si(double actual, double expected) {
  EXPECT_NEAR(actual, expected, 1e-12 * std::abs(expected)) << "expected " << expected;
}

void expect_vec(const Vec3& actual, const Vec3& expected) {
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(actual[i], expected[i], 1e-12 * std::max(1.0, std::abs(expected[i])))
        << "component " << i << " of (" << actual.transpose() << ")";
  }
}

/// what() of the InputError thrown by `f`; a test failure if none is thrown.
template <class F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got another exception: " << e.what();
    return {};
  }
  ADD_FAILURE() << "no InputError thrown";
  return {};
}

/// 1-based line of the first occurrence of `needle` in `text`.
int line_of(const std::string& text, const std::string& needle) {
  const auto pos = text.find(needle);
  if (pos == std::string::npos) {
    ADD_FAILURE() << "'" << needle << "' not in the scene text";
    return -1;
  }
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + pos, '\n'));
}

/// `text` with the first `from` replaced by `to` (which must be present).
std::string with(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  if (pos == std::string::npos) {
    ADD_FAILURE() << "'" << from << "' not in the scene text";
    return text;
  }
  return text.replace(pos, from.size(), to);
}

// A small valid scene that the error tests change one thing in.
const std::string kBase = R"(# minimal scene
[materials.copper]
density = "8930 kg/m^3"
youngs_modulus = "117 GPa"
poisson_ratio = 0.35

[[bodies]]
name = "bar"
material = "copper"
shape = "cylinder"
radius = "3.8 mm"
length = "25.4 mm"
velocity = "0 0 -190 m/s"

[grid]
cell_size = "0.76 mm"

[solver]
end_time = "80 us"
)";

Scene parse(const std::string& text, const std::vector<std::string>& overrides = {}) {
  return parse_scene(text, "inline.toml", "/scenes", overrides);
}

// ---------------------------------------------------------------------------------------------
// Valid scenes

TEST(Scene, TaylorBarParsesEveryKey) {
  const Scene s = load_scene(data("taylor_bar.toml"), {});
  EXPECT_EQ(s.source, data("taylor_bar.toml"));
  EXPECT_EQ(s.directory, std::string(MPM_TEST_DATA) + "/scenes");
  EXPECT_EQ(s.title, "Taylor bar");
  EXPECT_EQ(s.dimension, 3);

  ASSERT_EQ(s.materials.size(), 1u);
  const MaterialSpec& cu = s.materials[0];
  EXPECT_EQ(cu.name, "copper");
  expect_si(cu.density, 8930);
  expect_si(cu.youngs_modulus, 117e9);
  expect_si(cu.poisson_ratio, 0.35);
  EXPECT_EQ(cu.loc.line, 6);
  EXPECT_EQ(cu.loc.key, "materials.copper");
  EXPECT_EQ(cu.strength.model, StrengthModel::JohnsonCook);
  expect_si(cu.strength.A, 157e6);
  expect_si(cu.strength.B, 425e6);
  expect_si(cu.strength.n, 1.0);
  EXPECT_EQ(cu.strength.C, 0.0);
  expect_si(cu.strength.reference_rate, 1.0);
  expect_si(cu.strength.m, 1.0);
  expect_si(cu.strength.room_temperature, 293);
  expect_si(cu.strength.melt_temperature, 1356);
  expect_si(cu.strength.specific_heat, 383);
  expect_si(cu.strength.taylor_quinney, 0.9);
  EXPECT_TRUE(cu.strength.thermal());
  EXPECT_EQ(cu.eos.model, EosModel::MieGruneisen);
  expect_si(cu.eos.c0, 3940);
  expect_si(cu.eos.s, 1.49);
  expect_si(cu.eos.gamma0, 1.96);
  EXPECT_TRUE(cu.failure.enabled());
  expect_si(cu.failure.plastic_strain, 3.0);
  expect_si(cu.failure.pressure, -1.5e9);

  ASSERT_EQ(s.bodies.size(), 1u);
  const BodySpec& bar = s.bodies[0];
  EXPECT_EQ(bar.name, "bar");
  EXPECT_EQ(bar.material, 0);
  EXPECT_EQ(bar.shape, ShapeKind::Cylinder);
  expect_si(bar.radius, 3.8e-3);
  expect_si(bar.length, 25.4e-3);
  expect_vec(bar.translate, Vec3(0, 0, 0.1e-3));
  expect_vec(bar.velocity, Vec3(0, 0, -190));
  expect_vec(bar.scale, Vec3(1, 1, 1));
  expect_vec(bar.rotate_deg, Vec3(0, 0, 0));
  EXPECT_EQ(bar.particles_per_cell, 2);
  EXPECT_EQ(bar.loc.key, "bodies.bar");
  EXPECT_EQ(bar.loc.line, 34);

  expect_si(s.grid.cell_size, 0.76e-3);
  EXPECT_TRUE(s.grid.domain_given);
  expect_vec(s.grid.domain_min, Vec3(-10e-3, -10e-3, 0));
  expect_vec(s.grid.domain_max, Vec3(10e-3, 10e-3, 27e-3));
  EXPECT_EQ(s.grid.padding, 0.0);

  for (int f = 0; f < 6; ++f) {
    EXPECT_EQ(s.boundary.face[f], f == 4 ? BoundaryType::Slip : BoundaryType::Free) << f;
  }

  EXPECT_EQ(s.solver.scheme, Scheme::MUSL);
  expect_si(s.solver.cfl, 0.5);
  expect_si(s.solver.end_time, 80e-6);
  expect_si(s.solver.dt_max, 1e-6);
  expect_vec(s.solver.gravity, Vec3(0, 0, -9.81));
  EXPECT_EQ(s.solver.on_exit, OnExit::Stop);
  expect_si(s.solver.energy_growth_limit, 0.05);
  EXPECT_EQ(s.solver.max_steps, 0);
  expect_si(s.solver.bulk_linear, 0.06);
  expect_si(s.solver.bulk_quadratic, 1.5);

  EXPECT_EQ(s.output.frames, 10);
  expect_si(s.output.history_interval, 0.5e-6);
  EXPECT_EQ(s.output.fields, (std::vector<std::string>{"x", "v", "eps_p"}));
  EXPECT_EQ(s.output.precision, Precision::Float64);
  EXPECT_NE(s.toml.find("johnson-cook"), std::string::npos);
}

TEST(Scene, TwoBodiesMixedForms) {
  const Scene s = parse_scene(
      [] {
        std::ifstream in(data("two_bodies.toml"));
        std::stringstream ss;
        ss << in.rdbuf();
        return ss.str();
      }(),
      "two_bodies.toml", "/work/scenes", {});
  // Materials are numbered in alphabetical order of their names.
  ASSERT_EQ(s.materials.size(), 2u);
  EXPECT_EQ(s.materials[0].name, "aluminium");
  EXPECT_EQ(s.materials[1].name, "steel");
  EXPECT_EQ(s.material_index("steel"), 1);
  EXPECT_EQ(s.material_index("aluminium"), 0);
  EXPECT_EQ(s.material_index("brass"), -1);
  expect_si(s.materials[0].density, 2700);  // 2.7 g/cm^3
  expect_si(s.materials[0].youngs_modulus, 70e9);
  EXPECT_EQ(s.materials[0].strength.model, StrengthModel::Elastic);
  EXPECT_EQ(s.materials[0].eos.model, EosModel::Linear);
  EXPECT_FALSE(s.materials[0].failure.enabled());
  expect_si(s.materials[1].density, 7850);
  EXPECT_EQ(s.materials[1].strength.model, StrengthModel::J2);
  expect_si(s.materials[1].strength.A, 350e6);
  expect_si(s.materials[1].strength.B, 275e6);
  expect_si(s.materials[1].strength.n, 0.36);
  EXPECT_FALSE(s.materials[1].strength.thermal());

  ASSERT_EQ(s.bodies.size(), 3u);
  const BodySpec& plate = s.bodies[0];
  EXPECT_EQ(plate.name, "plate");
  EXPECT_EQ(plate.material, 0);
  EXPECT_EQ(plate.shape, ShapeKind::Box);
  expect_vec(plate.size, Vec3(0.02, 0.02, 0.002));
  expect_vec(plate.rotate_deg, Vec3(0, 0, 0.5 * 180 / std::numbers::pi));
  expect_vec(plate.scale, Vec3(2, 2, 2));

  const BodySpec& ball = s.bodies[1];
  EXPECT_EQ(ball.material, 1);
  EXPECT_EQ(ball.shape, ShapeKind::Sphere);
  expect_si(ball.radius, 2.5e-3);
  expect_vec(ball.translate, Vec3(0, 0, 5e-3));
  expect_vec(ball.velocity, Vec3(0, 0, -1000));
  expect_vec(ball.scale, Vec3(1, 1, 0.5));
  expect_vec(ball.rotate_deg, Vec3(0, 90, 0));  // plain numbers are degrees
  EXPECT_EQ(ball.particles_per_cell, 3);

  const BodySpec& part = s.bodies[2];
  EXPECT_EQ(part.shape, ShapeKind::Mesh);
  EXPECT_EQ(part.mesh_path, "/work/scenes/meshes/part.stl");

  expect_si(s.grid.cell_size, 0.5e-3);
  EXPECT_FALSE(s.grid.domain_given);
  expect_si(s.grid.padding, 1e-3);
  EXPECT_EQ(s.solver.scheme, Scheme::USL);  // "usl": case-insensitive
  expect_si(s.solver.end_time, 2e-5);
  EXPECT_EQ(s.solver.bulk_linear, 0.0);
  EXPECT_EQ(s.solver.bulk_quadratic, 0.0);
  EXPECT_EQ(s.solver.on_exit, OnExit::Remove);
  EXPECT_EQ(s.solver.max_steps, 1000);
  EXPECT_EQ(s.title, "");
}

TEST(Scene, PlaneStrain) {
  const Scene s = load_scene(data("plane_strain.toml"), {});
  EXPECT_EQ(s.dimension, 2);
  ASSERT_EQ(s.bodies.size(), 2u);
  EXPECT_EQ(s.bodies[0].shape, ShapeKind::Sphere);
  expect_vec(s.bodies[0].translate, Vec3(0, 5e-3, 0));
  expect_vec(s.bodies[0].velocity, Vec3(0, -100, 0));
  expect_vec(s.bodies[0].rotate_deg, Vec3(0, 0, 30));
  expect_vec(s.bodies[0].scale, Vec3(1, 1, 1));
  expect_vec(s.bodies[1].size, Vec3(20e-3, 4e-3, 0));
  expect_vec(s.bodies[1].rotate_deg, Vec3(0, 0, 15));
  expect_vec(s.solver.gravity, Vec3(0, -9.81, 0));
  EXPECT_EQ(s.boundary.face[2], BoundaryType::Fixed);
  EXPECT_EQ(s.boundary.face[0], BoundaryType::Free);
  expect_si(s.grid.padding, 0.5e-3);  // default: two cells
}

TEST(Scene, Defaults) {
  const Scene s = parse(kBase);
  EXPECT_EQ(s.source, "inline.toml");
  EXPECT_EQ(s.directory, "/scenes");
  EXPECT_EQ(s.title, "");
  EXPECT_EQ(s.dimension, 3);
  const MaterialSpec& m = s.materials.at(0);
  EXPECT_EQ(m.strength.model, StrengthModel::Elastic);
  EXPECT_EQ(m.eos.model, EosModel::Linear);
  EXPECT_FALSE(m.failure.enabled());
  const BodySpec& b = s.bodies.at(0);
  expect_vec(b.scale, Vec3(1, 1, 1));
  expect_vec(b.rotate_deg, Vec3::Zero());
  expect_vec(b.translate, Vec3::Zero());
  EXPECT_EQ(b.particles_per_cell, 2);
  EXPECT_FALSE(s.grid.domain_given);
  expect_si(s.grid.padding, 2 * 0.76e-3);
  for (auto f : s.boundary.face) EXPECT_EQ(f, BoundaryType::Free);
  EXPECT_EQ(s.solver.scheme, Scheme::MUSL);
  EXPECT_EQ(s.solver.cfl, 0.5);
  EXPECT_EQ(s.solver.dt_max, std::numeric_limits<double>::infinity());
  EXPECT_EQ(s.solver.on_exit, OnExit::Stop);
  EXPECT_EQ(s.solver.energy_growth_limit, 0.05);
  EXPECT_EQ(s.solver.max_steps, 0);
  EXPECT_EQ(s.solver.bulk_linear, 0.06);
  EXPECT_EQ(s.solver.bulk_quadratic, 1.5);
  expect_vec(s.solver.gravity, Vec3::Zero());
  EXPECT_EQ(s.output.frames, 10);
  EXPECT_EQ(s.output.history_interval, 0.0);
  EXPECT_TRUE(s.output.fields.empty());
  EXPECT_EQ(s.output.precision, Precision::Float64);
}

TEST(Scene, OptionalForms) {
  // Plain numbers are SI; unit-less strings too; bulk_viscosity = true keeps the defaults.
  Scene s = parse(with(with(kBase, R"(density = "8930 kg/m^3")", "density = 8930"),
                       R"(end_time = "80 us")",
                       "end_time = \"8e-5\"\nbulk_viscosity = true\ncfl = 1\n"
                       "gravity = [0, 0, -9.81]\ndt_max = 1e-6"));
  expect_si(s.materials[0].density, 8930);
  expect_si(s.solver.end_time, 8e-5);
  expect_si(s.solver.bulk_linear, 0.06);
  expect_si(s.solver.cfl, 1.0);
  expect_vec(s.solver.gravity, Vec3(0, 0, -9.81));
  // A thermal Johnson-Cook model with defaults for the optional keys.
  s = parse(kBase + R"TOML(
[materials.copper.strength]
model = "johnson-cook"
A = 157e6
m = 1.09
melt_temperature = "1356 K"
specific_heat = "0.383 J/(g*K)"
)TOML");
  const StrengthSpec& jc = s.materials[0].strength;
  EXPECT_EQ(jc.B, 0.0);
  EXPECT_EQ(jc.n, 1.0);
  EXPECT_EQ(jc.C, 0.0);
  EXPECT_EQ(jc.reference_rate, 1.0);
  EXPECT_EQ(jc.room_temperature, 293.0);
  expect_si(jc.specific_heat, 383);
  EXPECT_EQ(jc.taylor_quinney, 0.9);
  // Failure by pressure only.
  s = parse(kBase + "[materials.copper.failure]\npressure = \"-1.5 GPa\"\n");
  EXPECT_TRUE(s.materials[0].failure.enabled());
  EXPECT_EQ(s.materials[0].failure.plastic_strain, std::numeric_limits<double>::infinity());
  expect_si(s.materials[0].failure.pressure, -1.5e9);
  // [grid.domain] as a table and a vector given as an array of quantity strings.
  s = parse(kBase + "[grid.domain]\nmin = [\"-1 cm\", \"-1 cm\", \"0 cm\"]\nmax = \"1 1 3 cm\"\n");
  EXPECT_TRUE(s.grid.domain_given);
  expect_vec(s.grid.domain_min, Vec3(-0.01, -0.01, 0));
  expect_vec(s.grid.domain_max, Vec3(0.01, 0.01, 0.03));
  // Boundary: `all` then one face.
  s = parse(kBase + "[boundary]\nall = \"fixed\"\nz_min = \"slip\"\n");
  EXPECT_EQ(s.boundary.face[0], BoundaryType::Fixed);
  EXPECT_EQ(s.boundary.face[4], BoundaryType::Slip);
  EXPECT_EQ(s.boundary.face[5], BoundaryType::Fixed);
}

/// The ```toml blocks of docs/scene.md that start with "# Example:" (complete scenes).
std::vector<std::string> doc_examples() {
  std::ifstream in(std::string(MPM_TEST_DATA) + "/../../docs/scene.md");
  EXPECT_TRUE(in.good()) << "docs/scene.md not found";
  std::vector<std::string> blocks;
  std::string line, block;
  bool inside = false;
  while (std::getline(in, line)) {
    if (!inside && line == "```toml") {
      inside = true;
      block.clear();
    } else if (inside && line == "```") {
      inside = false;
      if (block.rfind("# Example:", 0) == 0) blocks.push_back(block);
    } else if (inside) {
      block += line + "\n";
    }
  }
  return blocks;
}

TEST(Scene, DocumentationExamplesParse) {
  const auto examples = doc_examples();
  ASSERT_GE(examples.size(), 2u);
  for (const auto& text : examples) {
    SCOPED_TRACE(text.substr(0, text.find('\n')));
    EXPECT_NO_THROW(parse_scene(text, "docs/scene.md", "docs", {}));
  }
  // The first one is the copper Taylor bar of the reference.
  const Scene s = parse_scene(examples[0], "docs/scene.md", "docs", {});
  ASSERT_EQ(s.bodies.size(), 1u);
  EXPECT_EQ(s.bodies[0].shape, ShapeKind::Cylinder);
  expect_si(s.bodies[0].radius, 3.8e-3);
  expect_si(s.bodies[0].length, 25.4e-3);
  expect_vec(s.bodies[0].velocity, Vec3(0, 0, -190));
  EXPECT_EQ(s.boundary.face[4], BoundaryType::Slip);
  expect_si(s.grid.domain_min.z(), 0.0);
  const MaterialSpec& cu = s.materials.at(0);
  EXPECT_EQ(cu.strength.model, StrengthModel::JohnsonCook);
  expect_si(cu.strength.A, 157e6);
  expect_si(cu.strength.B, 425e6);
  expect_si(cu.strength.n, 1.0);
  EXPECT_EQ(cu.strength.C, 0.0);
  EXPECT_EQ(cu.eos.model, EosModel::MieGruneisen);
  expect_si(cu.eos.c0, 3940);
  expect_si(cu.eos.s, 1.49);
  expect_si(cu.eos.gamma0, 1.96);
}

// ---------------------------------------------------------------------------------------------
// Mistakes in files: the message names the file, the line and the key.

struct FileCase {
  const char* file;
  int line;
  const char* says;  ///< must appear right after "<file>:<line>: "
};

TEST(SceneErrors, FilesNameFileLineAndKey) {
  const FileCase cases[] = {
      {"bad_syntax.toml", 3, "TOML syntax error: "},
      {"bad_unknown_key.toml", 7,
       "materials.copper.densty: unknown key (expected one of: density, youngs_modulus, "
       "poisson_ratio, shear_modulus, strength, eos, failure)"},
      {"bad_unknown_top.toml", 19,
       "outptu: unknown key (expected one of: scene, materials, bodies, loads, contact, grid, "
       "boundary, "
       "solver, "
       "output, rebar)"},
      {"bad_unknown_nested.toml", 9, "materials.copper.strength.hardening: unknown key"},
      {"bad_unknown_material.toml", 8,
       "bodies.bar.material: unknown material 'copr' (known: copper)"},
      {"bad_negative_density.toml", 2, "materials.copper.density: must be > 0, got '-8930 kg/m^3'"},
      {"bad_poisson_half.toml", 4,
       "materials.copper.poisson_ratio: must be below 0.5 (incompressible materials are not "
       "supported), got 0.5"},
      {"bad_poisson_06.toml", 4,
       "materials.copper.poisson_ratio: must be below 0.5 (incompressible materials are not "
       "supported), got 0.6"},
      {"bad_unit_dimension.toml", 12,
       "materials.copper.density: expected a density (kg/m^3), got '8930 m/s' (a velocity)"},
      {"bad_missing_key.toml", 5,
       "materials.copper: missing required key 'density' (a density, e.g. \"8930 kg/m^3\")"},
      {"bad_vector_length.toml", 12,
       "bodies.bar.velocity: expected 3 components (x y z), got 2 in '0 -190 m/s'"},
      {"bad_2d_cylinder.toml", 12,
       "bodies.bar.shape: shape \"cylinder\" is not available in 2D scenes; use box, sphere (a "
       "disk) or ogive (its axial section)"},
      {"bad_2d_z_face.toml", 22, "boundary.z_min: not available in 2D scenes"},
  };
  for (const auto& c : cases) {
    const std::string path = data(c.file);
    const std::string e = input_error([&] { load_scene(path, {}); });
    const std::string expected = path + ":" + std::to_string(c.line) + ": " + c.says;
    EXPECT_EQ(e.substr(0, expected.size()), expected) << c.file << "\n  got: " << e;
  }
}

TEST(SceneErrors, InputErrorCarriesWhereAndMessage) {
  try {
    load_scene(data("bad_unit_dimension.toml"), {});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where(), data("bad_unit_dimension.toml") + ":12: materials.copper.density");
    EXPECT_EQ(e.message(), "expected a density (kg/m^3), got '8930 m/s' (a velocity)");
  }
}

// Mistakes written into the base scene: `from` is replaced by `to`; the error must be at the
// line holding `at` (in the changed text) and contain `says`.
struct Case {
  const char* name;
  std::string from, to;
  std::string at;    ///< text on the expected line; empty: no line (file-level message)
  std::string says;  ///< expected after "inline.toml:<line>: "
};

TEST(SceneErrors, InlineCases) {
  const std::string end = "end_time = \"80 us\"";
  const std::string body_end = "velocity = \"0 0 -190 m/s\"";
  const std::string mat_end = "poisson_ratio = 0.35";
  const std::string twod = "[scene]\ndimension = 2\n";
  const std::vector<Case> cases = {
      {"wrong TOML type for a quantity", "density = \"8930 kg/m^3\"", "density = true",
       "density = true",
       "materials.copper.density: expected a density (kg/m^3), got true (a boolean)"},
      {"unknown unit", "radius = \"3.8 mm\"", "radius = \"3.8 mmm\"", "radius",
       "bodies.bar.radius: expected a length (m): unknown unit 'mmm' in '3.8 mmm'"},
      {"poisson ratio -1", mat_end, "poisson_ratio = -1", "poisson_ratio",
       "materials.copper.poisson_ratio: must be above -1, got -1"},
      {"poisson ratio with a unit", mat_end, "poisson_ratio = \"0.3 m\"", "poisson_ratio",
       "materials.copper.poisson_ratio: expected a number, got '0.3 m' (a length)"},
      {"integer expected", body_end, body_end + "\nparticles_per_cell = 2.5", "particles_per",
       "bodies.bar.particles_per_cell: expected an integer, got 2.5 (a floating-point number)"},
      {"particles per cell range", body_end, body_end + "\nparticles_per_cell = 9", "particles_per",
       "bodies.bar.particles_per_cell: must be between 1 and 8, got 9"},
      {"particle spacing and particles per cell", body_end,
       body_end + "\nparticles_per_cell = 3\nparticle_spacing = \"0.2 mm\"", "particle_spacing",
       "bodies.bar.particle_spacing: give either particles_per_cell (the spacing is the cell size "
       "over it) or particle_spacing, not both"},
      {"particle spacing above the cell", body_end, body_end + "\nparticle_spacing = \"1 mm\"",
       "particle_spacing",
       "bodies.bar.particle_spacing: expected a spacing from grid.cell_size / 16 to "
       "grid.cell_size (0.0475 mm to 0.76 mm): coarser particles leave cells inside the body "
       "empty (got 1 mm)"},
      {"particle spacing below a sixteenth of the cell", body_end,
       body_end + "\nparticle_spacing = \"0.04 mm\"", "particle_spacing",
       "bodies.bar.particle_spacing: expected a spacing from grid.cell_size / 16 to "
       "grid.cell_size (0.0475 mm to 0.76 mm): finer particles than 16 per cell along an axis "
       "(got 0.04 mm; refine the cells instead)"},
      {"particle spacing not a length", body_end, body_end + "\nparticle_spacing = \"0.2 kg\"",
       "particle_spacing", "bodies.bar.particle_spacing: expected a length"},
      {"scale zero", body_end, body_end + "\nscale = \"1 0 1\"", "scale",
       "bodies.bar.scale: every component must be > 0, got '1 0 1'"},
      {"vector with wrong unit", body_end, "velocity = \"0 0 -190 m\"", "velocity",
       "bodies.bar.velocity: expected a vector of 3 components (x y z), each a velocity (m/s)"},
      {"vector as a number", body_end, "velocity = 190", "velocity",
       "bodies.bar.velocity: expected a vector of 3 components"},
      {"vector array element", body_end, "velocity = [0, 0, \"-190 m\"]", "velocity",
       "bodies.bar.velocity[2]: expected a velocity (m/s), got '-190 m' (a length)"},
      {"vector array length", body_end, "velocity = [0, -190]", "velocity",
       "bodies.bar.velocity: expected 3 components (x y z), got 2"},
      {"unknown key in a body", body_end, body_end + "\ncolour = \"red\"", "colour",
       "bodies.bar.colour: unknown key (expected one of: name, material, shape"},
      {"body without name", "name = \"bar\"", "", "[[bodies]]",
       "bodies[0]: missing required key 'name'"},
      {"bad body name", "name = \"bar\"", "name = \"my bar\"", "name =",
       "bodies[0].name: a body name may contain only letters, digits, '_' and '-', got 'my bar'"},
      {"duplicate body name", end,
       end + "\n[[bodies]]\nname = \"bar\"\nmaterial = \"copper\"\nshape = \"sphere\"\n"
             "radius = \"1 mm\"",
       "name = \"bar\"\nmaterial = \"copper\"\nshape = \"sphere\"",
       "bodies.bar.name: duplicate body name 'bar' (first used at inline.toml:8)"},
      {"unknown shape", "shape = \"cylinder\"", "shape = \"cone\"", "shape",
       "bodies.bar.shape: expected one of \"box\", \"cylinder\", \"sphere\", \"ogive\", "
       "\"mesh\", got 'cone'"},
      {"missing shape", "shape = \"cylinder\"\n", "", "[[bodies]]",
       "bodies.bar: missing required key 'shape'"},
      {"box without size", "shape = \"cylinder\"", "shape = \"box\"", "[[bodies]]",
       "bodies.bar: missing required key 'size'"},
      {"key of another shape", "length = \"25.4 mm\"", "length = \"25.4 mm\"\nsize = \"1 1 1 mm\"",
       "size", "bodies.bar.size: not used with shape = \"cylinder\" (this key is for box)"},
      {"sphere with length", "shape = \"cylinder\"", "shape = \"sphere\"", "length",
       "bodies.bar.length: not used with shape = \"sphere\" (this key is for cylinder and ogive)"},
      {"ogive without crh", "shape = \"cylinder\"\nradius = \"3.8 mm\"",
       "shape = \"ogive\"\ndiameter = \"7.6 mm\"", "[[bodies]]",
       "bodies.bar: missing required key 'crh' (a number, e.g. 3.0; the nose's arc radius in "
       "shank diameters, at least 0.5)"},
      {"ogive with radius", "shape = \"cylinder\"", "shape = \"ogive\"\ndiameter = 0.0076\ncrh = 3",
       "radius",
       "bodies.bar.radius: not used with shape = \"ogive\" (this key is for cylinder and "
       "sphere)"},
      {"diameter on a cylinder", body_end, body_end + "\ndiameter = \"7.6 mm\"", "diameter",
       "bodies.bar.diameter: not used with shape = \"cylinder\" (this key is for ogive)"},
      {"2D mesh", "shape = \"cylinder\"\nradius = \"3.8 mm\"\nlength = \"25.4 mm\"",
       "shape = \"mesh\"\nfile = \"a.stl\"", "shape",
       "bodies.bar.shape: shape \"mesh\" is not available in 2D scenes; use box, sphere (a "
       "disk) or ogive (its axial section)"},
      {"2D three-component velocity",
       "shape = \"cylinder\"\nradius = \"3.8 mm\"\nlength = \"25.4 mm\"",
       "shape = \"sphere\"\nradius = \"3.8 mm\"", "velocity",
       "bodies.bar.velocity: expected 2 components (x y), got 3 in '0 0 -190 m/s'"},
      {"2D rotate vector", "shape = \"cylinder\"\nradius = \"3.8 mm\"\nlength = \"25.4 mm\"",
       "shape = \"sphere\"\nradius = \"3.8 mm\"\nrotate = \"0 0 30 deg\"", "rotate",
       "bodies.bar.rotate: expected a single angle about z in 2D scenes"},
      {"missing grid", "[grid]\ncell_size = \"0.76 mm\"\n", "", "",
       "grid: missing required table [grid] (cell_size is required)"},
      {"missing solver", "[solver]\n" + end, "", "",
       "solver: missing required table [solver] (end_time is required)"},
      {"missing end_time", end, "cfl = 0.3", "[solver]",
       "solver: missing required key 'end_time' (a time, e.g. \"80 us\")"},
      {"bodies as a table", "[[bodies]]", "[bodies]", "[bodies]",
       "bodies: expected an array of tables ([[bodies]], note the double brackets), got a table"},
      {"j2 without A", mat_end, mat_end + "\nstrength = { model = \"j2\", B = \"1 MPa\" }",
       "strength",
       "materials.copper.strength: missing required key 'A' (a pressure, e.g. \"157 MPa\")"},
      {"elastic with A", mat_end, mat_end + "\nstrength.A = \"1 MPa\"", "strength",
       "materials.copper.strength.A: not used by the elastic model"},
      {"j2 with C", mat_end,
       mat_end + "\n[materials.copper.strength]\nmodel = \"j2\"\nA = 1e8\nC = 0.1", "C = 0.1",
       "materials.copper.strength.C: not used by the j2 model (only by \"johnson-cook\")"},
      {"unknown strength model", mat_end, mat_end + "\nstrength.model = \"jc\"", "strength",
       "materials.copper.strength.model: expected one of \"elastic\", \"j2\", \"johnson-cook\", "
       "\"bilinear\", \"hjc\", got 'jc'"},
      {"bilinear with A", mat_end,
       mat_end + "\n[materials.copper.strength]\nmodel = \"bilinear\"\nyield_stress = "
                 "\"1.43 GPa\"\ntangent_modulus = \"14.759 GPa\"\nA = 1e8",
       "A = 1e8",
       "materials.copper.strength.A: not used by the bilinear model (its keys: yield_stress, "
       "tangent_modulus)"},
      {"bilinear without tangent modulus", mat_end,
       mat_end + "\n[materials.copper.strength]\nmodel = \"bilinear\"\nyield_stress = 1e8",
       "[materials.copper.strength]",
       "materials.copper.strength: missing required key 'tangent_modulus' (a pressure, e.g. "
       "\"14.759 GPa\"; the slope after yield, below youngs_modulus)"},
      {"bilinear tangent above E", mat_end,
       mat_end + "\n[materials.copper.strength]\nmodel = \"bilinear\"\nyield_stress = "
                 "1e8\ntangent_modulus = \"117 GPa\"",
       "tangent_modulus",
       "materials.copper.strength.tangent_modulus: must be below youngs_modulus (1.17e+11 Pa)"},
      {"j2 with tangent modulus", mat_end,
       mat_end + "\n[materials.copper.strength]\nmodel = \"j2\"\nA = 1e8\ntangent_modulus = 1e9",
       "tangent_modulus",
       "materials.copper.strength.tangent_modulus: not used by the j2 model (only by "
       "\"bilinear\")"},
      {"thermal JC without melt temperature", mat_end,
       mat_end + "\n[materials.copper.strength]\nmodel = \"johnson-cook\"\nA = 1e8\nm = 1\n"
                 "specific_heat = 383",
       "[materials.copper.strength]",
       "materials.copper.strength: missing required key 'melt_temperature' (a temperature, e.g. "
       "\"1356 K\"; required when m > 0)"},
      {"melt below room", mat_end,
       mat_end + "\n[materials.copper.strength]\nmodel = \"johnson-cook\"\nA = 1e8\nm = 1\n"
                 "specific_heat = 383\nmelt_temperature = \"250 K\"",
       "melt_temperature",
       "materials.copper.strength.melt_temperature: must be above room_temperature (293 K), got "
       "'250 K'"},
      {"taylor quinney above 1", mat_end,
       mat_end + "\n[materials.copper.strength]\nmodel = \"johnson-cook\"\nA = 1e8\n"
                 "taylor_quinney = 1.5",
       "taylor_quinney",
       "materials.copper.strength.taylor_quinney: must be between 0 and 1, got 1.5"},
      {"reference rate with a wrong unit", mat_end,
       mat_end + "\n[materials.copper.strength]\nmodel = \"johnson-cook\"\nA = 1e8\n"
                 "reference_rate = \"1 s\"",
       "reference_rate",
       "materials.copper.strength.reference_rate: expected a rate (1/s), got '1 s' (a time)"},
      {"mie-gruneisen without c0", mat_end,
       mat_end + "\n[materials.copper.eos]\nmodel = \"mie-gruneisen\"\ns = 1.49\ngamma0 = 2",
       "[materials.copper.eos]",
       "materials.copper.eos: missing required key 'c0' (a velocity, e.g. \"3940 m/s\")"},
      {"linear eos with c0", mat_end, mat_end + "\neos.c0 = \"3940 m/s\"", "eos.c0",
       "materials.copper.eos.c0: not used by the linear model"},
      {"empty failure", mat_end, mat_end + "\n[materials.copper.failure]",
       "[materials.copper.failure]", "materials.copper.failure: empty table"},
      {"positive failure pressure", mat_end, mat_end + "\nfailure.pressure = \"1 GPa\"", "failure",
       "materials.copper.failure.pressure: must be < 0, got '1 GPa'"},
      {"materials not tables", mat_end, mat_end + "\n[materials]\nbrass = 3", "brass",
       "materials.brass: expected a table ([materials.brass]), got 3 (an integer)"},
      {"domain max below min", "cell_size = \"0.76 mm\"",
       "cell_size = \"0.76 mm\"\ndomain = { min = \"0 0 0 mm\", max = \"1 -1 1 mm\" }", "domain",
       "grid.domain.max: must be above min in every component, but y: max -0.001 m <= min 0 m"},
      {"domain without max", "cell_size = \"0.76 mm\"",
       "cell_size = \"0.76 mm\"\ndomain = { min = \"0 0 0 mm\" }", "domain",
       "grid.domain: missing required key 'max'"},
      {"domain and padding", "cell_size = \"0.76 mm\"",
       "cell_size = \"0.76 mm\"\ndomain = { min = \"0 0 0 mm\", max = \"1 1 1 mm\" }\n"
       "padding = \"1 mm\"",
       "padding", "grid.padding: cannot be combined with grid.domain"},
      {"negative padding", "cell_size = \"0.76 mm\"", "cell_size = \"0.76 mm\"\npadding = -1",
       "padding", "grid.padding: must be >= 0, got -1"},
      {"bad boundary type", end, end + "\n[boundary]\nx_min = \"sticky\"", "sticky",
       "boundary.x_min: expected one of \"free\", \"slip\", \"fixed\", got 'sticky'"},
      {"bad scheme", end, end + "\nscheme = \"FLIP\"", "FLIP",
       "solver.scheme: expected one of \"USF\", \"USL\", \"MUSL\", \"APIC\", got 'FLIP'"},
      {"negative end time", end, "end_time = \"-1 us\"", "end_time",
       "solver.end_time: must be > 0, got '-1 us'"},
      {"zero dt_max", end, end + "\ndt_max = 0", "dt_max", "solver.dt_max: must be > 0, got 0"},
      {"bulk viscosity number", end, end + "\nbulk_viscosity = 3", "bulk_viscosity",
       "solver.bulk_viscosity: expected a table { linear = 0.06, quadratic = 1.5 }, or false"},
      {"bulk viscosity negative", end, end + "\nbulk_viscosity = { linear = -0.1 }",
       "bulk_viscosity", "solver.bulk_viscosity.linear: must be >= 0, got -0.1"},
      {"negative max_steps", end, end + "\nmax_steps = -1", "max_steps",
       "solver.max_steps: must be >= 0, got -1"},
      {"zero frames", end, end + "\n[output]\nframes = 0", "frames",
       "output.frames: must be between 1 and"},
      {"field not a string", end, end + "\n[output]\nfields = [\"x\", 3]", "fields",
       "output.fields[1]: expected a string, got 3 (an integer)"},
      {"bad precision", end, end + "\n[output]\nprecision = \"half\"", "precision",
       "output.precision: expected one of \"float64\", \"float32\", got 'half'"},
      {"negative history interval", end, end + "\n[output]\nhistory_interval = \"-1 us\"",
       "history_interval", "output.history_interval: must be >= 0, got '-1 us'"},
      {"dimension 4", "# minimal scene", "[scene]\ndimension = 4", "dimension",
       "scene.dimension: must be 3, or 2 (the x-y plane), got 4"},
      {"title not a string", "# minimal scene", "[scene]\ntitle = 3", "title",
       "scene.title: expected a string, got 3 (an integer)"},
      {"unknown key in [scene]", "# minimal scene", "[scene]\ndimensions = 3", "dimensions",
       "scene.dimensions: unknown key (expected one of: title, dimension, geometry)"},
      {"3D plane stress", "# minimal scene", "[scene]\ngeometry = \"plane-stress\"", "geometry",
       "scene.geometry: is for 2D scenes (dimension = 2): \"plane-strain\", \"plane-stress\" or "
       "\"axisymmetric\""},
      {"bad geometry", "# minimal scene", "[scene]\ndimension = 2\ngeometry = \"shell\"", "shell",
       "scene.geometry: expected one of \"plane-strain\", \"axisymmetric\", \"plane-stress\", got "
       "'shell'"},
  };
  for (const auto& c : cases) {
    std::string text = with(kBase, c.from, c.to);
    if (std::string(c.name).rfind("2D", 0) == 0) text = twod + text;
    const std::string e = input_error([&] { parse(text); });
    const std::string expected =
        c.at.empty() ? "inline.toml: " + c.says
                     : "inline.toml:" + std::to_string(line_of(text, c.at)) + ": " + c.says;
    EXPECT_EQ(e.substr(0, expected.size()), expected) << c.name << "\n  got: " << e;
  }
}

TEST(SceneErrors, MissingTopLevelTables) {
  EXPECT_EQ(input_error([] { parse(""); }),
            "inline.toml: materials: missing required table [materials] (one "
            "[materials.<name>] table per material)");
  const std::string no_bodies =
      kBase.substr(0, kBase.find("[[bodies]]")) + "[grid]\ncell_size = 1\n";
  EXPECT_EQ(input_error([&] { parse(no_bodies); }),
            "inline.toml: bodies: missing required array [[bodies]] (at least one body)");
}

TEST(SceneErrors, UnreadableFile) {
  const std::string missing = data("does_not_exist.toml");
  const std::string e = input_error([&] { load_scene(missing, {}); });
  EXPECT_EQ(e.rfind(missing + ": cannot read the scene file", 0), 0u) << e;
  const std::string dir = data("");
  const std::string d = input_error([&] { load_scene(dir, {}); });
  EXPECT_NE(d.find("it is a directory"), std::string::npos) << d;
}

TEST(Scene, LoadFromStdin) {
  std::istringstream in(kBase);
  std::streambuf* old = std::cin.rdbuf(in.rdbuf());
  Scene s;
  try {
    s = load_scene("-", {"solver.cfl=0.25"});
  } catch (...) {
    std::cin.rdbuf(old);
    throw;
  }
  std::cin.rdbuf(old);
  EXPECT_EQ(s.source, "<stdin>");
  EXPECT_EQ(s.bodies.size(), 1u);
  EXPECT_EQ(s.solver.cfl, 0.25);
}

// ---------------------------------------------------------------------------------------------
// --set overrides

TEST(SceneOverrides, ApplyByBodyNameAndIndex) {
  Scene s = parse(kBase, {"bodies.bar.velocity=\"0 0 -100 m/s\""});
  expect_vec(s.bodies[0].velocity, Vec3(0, 0, -100));
  s = parse(kBase, {"bodies.0.velocity=[0, 0, -50]", "bodies.0.particles_per_cell = 4"});
  expect_vec(s.bodies[0].velocity, Vec3(0, 0, -50));
  EXPECT_EQ(s.bodies[0].particles_per_cell, 4);
  // Later overrides win.
  s = parse(kBase, {"solver.cfl=0.3", "solver.cfl=0.2"});
  EXPECT_EQ(s.solver.cfl, 0.2);
}

TEST(SceneOverrides, SettingSpacingOrParticlesPerCellReplacesTheOther) {
  const std::string body_end = "velocity = \"0 0 -190 m/s\"";
  // The file gives particles_per_cell; --set particle_spacing switches this run to a spacing.
  const std::string n3 = with(kBase, body_end, body_end + "\nparticles_per_cell = 3");
  Scene s = parse(n3, {"bodies.bar.particle_spacing=0.2 mm"});
  expect_si(s.bodies[0].particle_spacing, 0.2e-3);
  EXPECT_DOUBLE_EQ(s.bodies[0].spacing(s.grid.cell_size), 0.2e-3);
  // The file gives particle_spacing; --set particles_per_cell switches back.
  const std::string sp = with(kBase, body_end, body_end + "\nparticle_spacing = \"0.2 mm\"");
  s = parse(sp);
  expect_si(s.bodies[0].spacing(s.grid.cell_size), 0.2e-3);
  s = parse(sp, {"bodies.bar.particles_per_cell=4"});
  EXPECT_EQ(s.bodies[0].particle_spacing, 0.0);
  EXPECT_DOUBLE_EQ(s.bodies[0].spacing(s.grid.cell_size), 0.76e-3 / 4);
  // Both from --set: the later wins, as for any key.
  s = parse(kBase, {"bodies.bar.particles_per_cell=4", "bodies.bar.particle_spacing=0.2 mm"});
  expect_si(s.bodies[0].particle_spacing, 0.2e-3);
  // The document a model carries (the scene with its overrides) parses to the same body.
  const Scene again = parse_scene(s.toml, "model", "/scenes", {});
  EXPECT_EQ(again.bodies[0].particle_spacing, s.bodies[0].particle_spacing);
  const Scene back =
      parse_scene(parse(sp, {"bodies.bar.particles_per_cell=4"}).toml, "model", "/scenes", {});
  EXPECT_EQ(back.bodies[0].particle_spacing, 0.0);
  EXPECT_EQ(back.bodies[0].particles_per_cell, 4);
}

TEST(SceneOverrides, ValuesAreTomlOrStrings) {
  Scene s = parse(kBase, {"solver.cfl=0.3", "grid.cell_size=\"0.38 mm\""});
  EXPECT_EQ(s.solver.cfl, 0.3);
  expect_si(s.grid.cell_size, 0.38e-3);
  // Not valid TOML: taken as a string.
  s = parse(kBase, {"grid.cell_size=0.38mm", "solver.end_time = 40 us", "solver.scheme=usf"});
  expect_si(s.grid.cell_size, 0.38e-3);
  expect_si(s.solver.end_time, 40e-6);
  EXPECT_EQ(s.solver.scheme, Scheme::USF);
  // Inline tables and arrays.
  s = parse(kBase, {"solver.bulk_viscosity={ linear = 0.1 }", "output.fields=[\"x\"]"});
  expect_si(s.solver.bulk_linear, 0.1);
  expect_si(s.solver.bulk_quadratic, 1.5);
  EXPECT_EQ(s.output.fields, std::vector<std::string>{"x"});
}

TEST(SceneOverrides, CreateMissingTables) {
  const Scene s = parse(kBase, {"output.frames=3", "materials.copper.strength.model=j2",
                                "materials.copper.strength.A=\"200 MPa\"", "boundary.z_min=slip",
                                "scene.title=Taylor test"});
  EXPECT_EQ(s.output.frames, 3);
  EXPECT_EQ(s.materials[0].strength.model, StrengthModel::J2);
  expect_si(s.materials[0].strength.A, 200e6);
  EXPECT_EQ(s.boundary.face[4], BoundaryType::Slip);
  EXPECT_EQ(s.title, "Taylor test");
  EXPECT_NE(s.toml.find("[output]"), std::string::npos) << s.toml;
}

TEST(SceneOverrides, MalformedOverrides) {
  struct Bad {
    const char* set;
    const char* says;  ///< the whole what()
  };
  const Bad cases[] = {
      {"solver.cfl", "--set solver.cfl: expected key=value, e.g. solver.cfl=0.3"},
      {"=0.3", "--set =0.3: empty key before '='"},
      {"solver.cfl=", "--set solver.cfl: empty value after '='"},
      {"solver..cfl=1", "--set solver..cfl: empty part in the key"},
      {"bodies.foo.velocity=1", "--set bodies.foo.velocity: unknown body 'foo' (known: bar)"},
      {"bodies.3.velocity=1",
       "--set bodies.3.velocity: no body with index 3 (the scene has 1, numbered from 0)"},
      {"bodies.bar=1", "--set bodies.bar: expected bodies.<name or index>.<key>"},
      {"solver.cfl.x=1",
       "--set solver.cfl.x: 'solver.cfl' is a floating-point number, not a "
       "table"},
  };
  for (const auto& c : cases) {
    std::string text = kBase + "cfl = 0.5\n";
    const std::string e = input_error([&] { parse(text, {c.set}); });
    EXPECT_EQ(e.substr(0, std::string(c.says).size()), c.says) << c.set << "\n  got: " << e;
  }
}

TEST(SceneOverrides, ErrorsInOverriddenValuesNameTheOverride) {
  EXPECT_EQ(input_error([] { parse(kBase, {"solver.cfl=-1"}); }),
            "--set solver.cfl: must be > 0, got -1");
  EXPECT_EQ(input_error([] { parse(kBase, {"grid.cell_size=0.38 mmm"}); }),
            "--set grid.cell_size: expected a length (m): unknown unit 'mmm' in '0.38 mmm' "
            "(known units: m, g, s, K, N, Pa, J, W, Hz, deg, rad; prefixes G M k c m u \u00b5 n "
            "p on m, s, g, N, Pa, J)");
  const std::string unknown = input_error([] { parse(kBase, {"solver.cfll=0.3"}); });
  EXPECT_EQ(unknown.rfind("--set solver.cfll: unknown key (expected one of: scheme", 0), 0u)
      << unknown;
  // By index: the message names the override and the body's key.
  EXPECT_EQ(input_error([] { parse(kBase, {"bodies.0.velocity=\"0 -1 m/s\""}); }),
            "--set bodies.0.velocity: bodies.bar.velocity: expected 3 components (x y z), got 2 "
            "in '0 -1 m/s'");
  // A table the override created.
  const std::string created = input_error([] { parse(kBase, {"materials.steel.density=7800"}); });
  EXPECT_EQ(created.rfind("--set materials.steel.density: materials.steel: missing required key "
                          "'youngs_modulus'",
                          0),
            0u)
      << created;
  // Inside an overridden inline table.
  EXPECT_EQ(input_error([] { parse(kBase, {"solver.bulk_viscosity={ quadratic = -1 }"}); }),
            "--set solver.bulk_viscosity: solver.bulk_viscosity.quadratic: must be >= 0, got -1");
  // Values from the file keep their lines.
  const std::string file = input_error([] {
    parse(with(kBase, "end_time = \"80 us\"", "end_time = \"0 us\""), {"solver.cfl=0.1"});
  });
  EXPECT_EQ(file.rfind("inline.toml:19: solver.end_time: must be > 0", 0), 0u) << file;
}

// ---------------------------------------------------------------------------------------------
// Scene::toml round trip

void expect_same(const Scene& a, const Scene& b) {
  EXPECT_EQ(a.title, b.title);
  EXPECT_EQ(a.dimension, b.dimension);
  ASSERT_EQ(a.materials.size(), b.materials.size());
  for (std::size_t i = 0; i < a.materials.size(); ++i) {
    const MaterialSpec &x = a.materials[i], &y = b.materials[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.density, y.density);
    EXPECT_EQ(x.youngs_modulus, y.youngs_modulus);
    EXPECT_EQ(x.poisson_ratio, y.poisson_ratio);
    EXPECT_EQ(x.strength.model, y.strength.model);
    EXPECT_EQ(x.strength.A, y.strength.A);
    EXPECT_EQ(x.strength.B, y.strength.B);
    EXPECT_EQ(x.strength.n, y.strength.n);
    EXPECT_EQ(x.strength.C, y.strength.C);
    EXPECT_EQ(x.strength.reference_rate, y.strength.reference_rate);
    EXPECT_EQ(x.strength.m, y.strength.m);
    EXPECT_EQ(x.strength.room_temperature, y.strength.room_temperature);
    EXPECT_EQ(x.strength.melt_temperature, y.strength.melt_temperature);
    EXPECT_EQ(x.strength.specific_heat, y.strength.specific_heat);
    EXPECT_EQ(x.strength.taylor_quinney, y.strength.taylor_quinney);
    EXPECT_EQ(x.eos.model, y.eos.model);
    EXPECT_EQ(x.eos.c0, y.eos.c0);
    EXPECT_EQ(x.eos.s, y.eos.s);
    EXPECT_EQ(x.eos.gamma0, y.eos.gamma0);
    EXPECT_EQ(x.failure.plastic_strain, y.failure.plastic_strain);
    EXPECT_EQ(x.failure.pressure, y.failure.pressure);
    EXPECT_EQ(x.loc.key, y.loc.key);
  }
  ASSERT_EQ(a.bodies.size(), b.bodies.size());
  for (std::size_t i = 0; i < a.bodies.size(); ++i) {
    const BodySpec &x = a.bodies[i], &y = b.bodies[i];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.material, y.material);
    EXPECT_EQ(x.shape, y.shape);
    EXPECT_EQ(x.size, y.size);
    EXPECT_EQ(x.radius, y.radius);
    EXPECT_EQ(x.length, y.length);
    EXPECT_EQ(x.crh, y.crh);
    EXPECT_EQ(x.mesh_path, y.mesh_path);
    EXPECT_EQ(x.scale, y.scale);
    EXPECT_EQ(x.rotate_deg, y.rotate_deg);
    EXPECT_EQ(x.translate, y.translate);
    EXPECT_EQ(x.velocity, y.velocity);
    EXPECT_EQ(x.particles_per_cell, y.particles_per_cell);
  }
  EXPECT_EQ(a.grid.cell_size, b.grid.cell_size);
  EXPECT_EQ(a.grid.domain_given, b.grid.domain_given);
  EXPECT_EQ(a.grid.domain_min, b.grid.domain_min);
  EXPECT_EQ(a.grid.domain_max, b.grid.domain_max);
  EXPECT_EQ(a.grid.padding, b.grid.padding);
  EXPECT_EQ(a.boundary.face, b.boundary.face);
  EXPECT_EQ(a.solver.scheme, b.solver.scheme);
  EXPECT_EQ(a.solver.cfl, b.solver.cfl);
  EXPECT_EQ(a.solver.end_time, b.solver.end_time);
  EXPECT_EQ(a.solver.dt_max, b.solver.dt_max);
  EXPECT_EQ(a.solver.bulk_linear, b.solver.bulk_linear);
  EXPECT_EQ(a.solver.bulk_quadratic, b.solver.bulk_quadratic);
  EXPECT_EQ(a.solver.gravity, b.solver.gravity);
  EXPECT_EQ(a.solver.on_exit, b.solver.on_exit);
  EXPECT_EQ(a.solver.energy_growth_limit, b.solver.energy_growth_limit);
  EXPECT_EQ(a.solver.max_steps, b.solver.max_steps);
  EXPECT_EQ(a.output.frames, b.output.frames);
  EXPECT_EQ(a.output.history_interval, b.output.history_interval);
  EXPECT_EQ(a.output.fields, b.output.fields);
  EXPECT_EQ(a.output.precision, b.output.precision);
  EXPECT_EQ(a.toml, b.toml);
}

TEST(SceneRoundTrip, TomlTextParsesToTheSameScene) {
  for (const char* file : {"taylor_bar.toml", "two_bodies.toml", "plane_strain.toml"}) {
    SCOPED_TRACE(file);
    const Scene a = load_scene(data(file), {});
    const Scene b = parse_scene(a.toml, a.source, a.directory, {});
    expect_same(a, b);
  }
}

TEST(SceneRoundTrip, OverridesAreInTheTomlText) {
  const std::vector<std::string> sets = {"bodies.bar.velocity=\"0 0 -250 m/s\"",
                                         "solver.cfl=0.1",
                                         "grid.cell_size=0.38mm",
                                         "output.frames=7",
                                         "materials.copper.failure.plastic_strain=2.5",
                                         "solver.bulk_viscosity={ linear = 0.1, quadratic = 1.0 }",
                                         "bodies.0.rotate=[10, 20, 30]"};
  const Scene a = load_scene(data("taylor_bar.toml"), sets);
  expect_vec(a.bodies[0].velocity, Vec3(0, 0, -250));
  expect_vec(a.bodies[0].rotate_deg, Vec3(10, 20, 30));
  EXPECT_EQ(a.output.frames, 7);
  EXPECT_EQ(a.materials[0].failure.plastic_strain, 2.5);
  // The text alone, without the overrides, gives the overridden scene.
  const Scene b = parse_scene(a.toml, a.source, a.directory, {});
  expect_same(a, b);
  EXPECT_NE(a.toml.find("-250 m/s"), std::string::npos) << a.toml;
  EXPECT_NE(a.toml.find("0.38mm"), std::string::npos) << a.toml;
}

TEST(SceneRoundTrip, FloatsKeepEveryDigit) {
  // Short numbers are written briefly...
  const Scene a = parse(kBase);
  EXPECT_NE(a.toml.find("poisson_ratio = 0.35\n"), std::string::npos) << a.toml;
  // ...and a number that needs 17 digits keeps all of them.
  const Scene b = parse(kBase, {"solver.cfl=0.30000000000000004", "grid.cell_size=7.6e-4"});
  EXPECT_EQ(b.solver.cfl, 0.1 + 0.2);
  const Scene c = parse_scene(b.toml, b.source, b.directory, {});
  EXPECT_EQ(c.solver.cfl, 0.1 + 0.2);
  EXPECT_EQ(c.grid.cell_size, 7.6e-4);
  expect_same(b, c);
}

}  // namespace
}  // namespace mpm
