// Scene keys of the implicit solver: defaults (the seed's), every key read, and mistakes
// reported with file, line and key.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "mpm/core/error.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm {
namespace {

const std::string kScene = R"(# 2D bar
[scene]
dimension = 2

[materials.bar]
density = 10
youngs_modulus = 1000
poisson_ratio = 0.3

[[bodies]]
name = "bar"
material = "bar"
shape = "box"
size = "0.3 0.3"

[grid]
cell_size = 0.1

[solver]
end_time = 10
)";

Scene parse(const std::string& extra, const std::vector<std::string>& overrides = {}) {
  return parse_scene(kScene + extra, "bar.toml", "/scenes", overrides);
}

std::string error(const std::string& extra, const std::vector<std::string>& overrides = {}) {
  try {
    parse(extra, overrides);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError for:\n" << extra;
  return {};
}

TEST(SceneImplicit, DefaultsAreTheSeeds) {
  Scene s = parse("");
  EXPECT_EQ(s.solver.type, SolverType::Explicit);
  s = parse("type = \"implicit\"\n");
  EXPECT_EQ(s.solver.type, SolverType::Implicit);
  const ImplicitSpec& m = s.solver.implicit;
  EXPECT_EQ(m.theta, 1.0);                          // 001 section 3: fully implicit
  EXPECT_EQ(m.formulation, Formulation::Momentum);  // section 3.2: the robust one
  EXPECT_EQ(m.krylov, KrylovMethod::GMRES);
  EXPECT_EQ(m.newton_tolerance, 1e-5);  // sections 3.1.1, 3.2.5
  EXPECT_EQ(m.linear_tolerance, 1e-3);
  EXPECT_EQ(m.derivative_step, 1e-5);  // section 3.2.2
  EXPECT_EQ(m.gmres_basis, 20);        // section 3.2.4
  EXPECT_EQ(m.ramp, 0.2);              // Tables 1-6: 20% a step
  EXPECT_EQ(m.dt_initial_multiple, 1.0);
  EXPECT_EQ(m.forcing, Forcing::EisenstatWalker);       // beyond the seed: measured to win
  EXPECT_EQ(m.preconditioner, Preconditioner::None);    // GMRES: the tangent is an option
  EXPECT_EQ(m.initial_guess, InitialGuess::Particles);  // the seed's v^k: with GMRES, wins
  const Scene v = parse("type = \"implicit\"\n", {"solver.implicit.formulation=velocity"});
  EXPECT_EQ(v.solver.implicit.krylov, KrylovMethod::CG);
  EXPECT_EQ(v.solver.implicit.preconditioner, Preconditioner::Tangent);  // with CG: wins
  EXPECT_EQ(v.solver.implicit.initial_guess, InitialGuess::Previous);    // with CG: wins
}

TEST(SceneImplicit, EveryKeyIsRead) {
  const Scene s = parse(R"(type = "implicit"
[solver.implicit]
theta = 0.5
formulation = "velocity"
newton_tolerance = 1e-6
linear_tolerance = 1e-4
derivative_step = 1e-4
gmres_basis = 30
gmres_restarts = 2
max_krylov = 50
max_newton = 12
max_line_search = 4
dt_initial_multiple = 10
dt_target_multiple = 100
ramp = 0.1
cut = 0.25
max_cuts = 3
forcing = "fixed"
preconditioner = "none"
initial_guess = "particles"
)");
  const ImplicitSpec& m = s.solver.implicit;
  EXPECT_EQ(m.theta, 0.5);
  EXPECT_EQ(m.formulation, Formulation::Velocity);
  EXPECT_EQ(m.krylov, KrylovMethod::CG);  // the velocity formulation's default
  EXPECT_EQ(m.newton_tolerance, 1e-6);
  EXPECT_EQ(m.linear_tolerance, 1e-4);
  EXPECT_EQ(m.derivative_step, 1e-4);
  EXPECT_EQ(m.gmres_basis, 30);
  EXPECT_EQ(m.gmres_restarts, 2);
  EXPECT_EQ(m.max_krylov, 50);
  EXPECT_EQ(m.max_newton, 12);
  EXPECT_EQ(m.max_line_search, 4);
  EXPECT_EQ(m.dt_initial_multiple, 10);
  EXPECT_EQ(m.dt_target_multiple, 100);
  EXPECT_EQ(m.ramp, 0.1);
  EXPECT_EQ(m.cut, 0.25);
  EXPECT_EQ(m.max_cuts, 3);
  EXPECT_EQ(m.forcing, Forcing::Fixed);
  EXPECT_EQ(m.preconditioner, Preconditioner::None);
  EXPECT_EQ(m.initial_guess, InitialGuess::Particles);  // not the velocity formulation's default
  // Velocity formulation with GMRES is allowed; --set reaches the table.
  const Scene g = parse("type = \"implicit\"\n",
                        {"solver.implicit.formulation=velocity", "solver.implicit.krylov=gmres"});
  EXPECT_EQ(g.solver.implicit.krylov, KrylovMethod::GMRES);
}

TEST(SceneImplicit, MistakesNameFileLineAndKey) {
  const std::string imp = "type = \"implicit\"\n[solver.implicit]\n";
  // Line numbers: kScene has 20 lines; "type" is line 21, the table header 22, its keys 23+.
  struct Case {
    std::string extra, expect;
  };
  const std::vector<Case> cases = {
      {"type = \"semi\"\n",
       "bar.toml:21: solver.type: expected one of \"explicit\", \"implicit\", got 'semi'"},
      {imp + "theta = 1.5\n", "bar.toml:23: solver.implicit.theta: must be between 0"},
      {imp + "theta = -0.1\n", "bar.toml:23: solver.implicit.theta: must be >= 0"},
      {imp + "formulation = \"flip\"\n",
       "bar.toml:23: solver.implicit.formulation: expected one of \"velocity\", \"momentum\""},
      {imp + "krylov = \"cg\"\n", "bar.toml:23: solver.implicit.krylov: CG needs a symmetric"},
      {imp + "newton_tol = 1e-5\n", "bar.toml:23: solver.implicit.newton_tol: unknown key"},
      {imp + "derivative_step = 0\n", "bar.toml:23: solver.implicit.derivative_step: must be > 0"},
      {imp + "gmres_basis = 0\n", "bar.toml:23: solver.implicit.gmres_basis: must be between 1"},
      {imp + "dt_initial_multiple = 10\ndt_target_multiple = 5\n",
       "bar.toml:24: solver.implicit.dt_target_multiple: must be >= dt_initial_multiple (10)"},
      {imp + "cut = 1\n", "bar.toml:23: solver.implicit.cut: must be below 1"},
      {imp + "forcing = \"ew\"\n",
       "bar.toml:23: solver.implicit.forcing: expected one of \"fixed\", \"eisenstat-walker\""},
      {imp + "initial_guess = \"last\"\n",
       "bar.toml:23: solver.implicit.initial_guess: expected one of \"particles\", \"previous\""},
      {"[solver.implicit]\ntheta = 1\n",
       "solver.implicit: is used only with solver.type = \"implicit\""},
      {"type = \"implicit\"\nscheme = \"USL\"\n",
       "bar.toml:22: solver.scheme: is for the explicit solver"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.extra);
    const std::string msg = error(c.extra);
    EXPECT_NE(msg.find(c.expect), std::string::npos) << msg;
  }
  // Through --set the override is named.
  const std::string msg = error("type = \"implicit\"\n", {"solver.implicit.theta=2"});
  EXPECT_NE(msg.find("--set solver.implicit.theta"), std::string::npos) << msg;
}

// A rigid body's contact: no-slip by default, frictionless along the `slip` axes.
TEST(SceneImplicit, RigidBodySlipAxes) {
  const std::string puller = R"(
[[bodies]]
name = "puller"
rigid = true
shape = "box"
size = "0.1 0.3"
velocity = "-0.001 0"
)";
  // The [solver] table ends kScene, so the body goes before it.
  auto scene = [&](const std::string& body_extra) {
    std::string text = kScene;
    text.insert(text.find("[grid]"), puller + body_extra + "\n");
    return text;
  };
  auto parse_text = [](const std::string& text, const std::vector<std::string>& sets = {}) {
    return parse_scene(text, "bar.toml", "/scenes", sets);
  };
  EXPECT_EQ(parse_text(scene("")).bodies[1].slip_axes, 0);
  EXPECT_EQ(parse_text(scene("slip = \"y\"")).bodies[1].slip_axes, 2);
  EXPECT_EQ(parse_text(scene("slip = \"y\""), {"bodies.puller.slip=none"}).bodies[1].slip_axes, 0);
  EXPECT_EQ(parse_text(scene(""), {"bodies.puller.slip=x"}).bodies[1].slip_axes, 1);
  auto fails = [&](const std::string& extra, const std::string& says) {
    const std::string text = scene(extra);
    try {
      parse_text(text);
      ADD_FAILURE() << "no InputError for " << extra;
    } catch (const InputError& e) {
      const std::string line =
          std::to_string(std::count(text.begin(), text.begin() + text.find(extra), '\n') + 1);
      EXPECT_EQ(std::string(e.what()), "bar.toml:" + line + ": bodies.puller.slip: " + says)
          << extra;
    }
  };
  fails("slip = \"z\"",
        "expected the axes along which the contact is frictionless, from x y, "
        "e.g. \"y\"; got 'z' in \"z\"");
  fails("slip = \"x y\"", "a body that slips along every axis holds nothing; leave one axis out");
  fails("slip = \"\"", "expected at least one axis from x y, e.g. \"y\", or \"none\"");
  // On a deformable body.
  std::string text = kScene;
  text.insert(text.find("\n[grid]"), "slip = \"y\"\n");
  try {
    parse_text(text);
    ADD_FAILURE() << "no InputError for slip on a deformable body";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "slip: only a rigid body has a contact to slip on (this body has a material)"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace mpm
