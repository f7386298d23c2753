// mpm-prep --target-error: the trade study's fit of the Taylor bar (examples/trade) turned
// into a cell size and particles per cell, for bars similar to the one it was measured on.
#include "mpm/prep/target_error.hpp"

#include <toml++/toml.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "mpm/core/error.hpp"
#include "mpm/prep/taylor_fit.hpp"

namespace mpm {

namespace {

constexpr const char* kWhere = "--target-error";

/// A measure's convergence: value / reference = inf + a (h / R0)^p, and the rms of the runs
/// about it (the scatter of the particles' tiling of the bar from one cell size to the next).
struct Convergence {
  double inf = 0, a = 0, p = 1, rms = 0;
  double at(double h_rel) const { return inf + a * std::pow(h_rel, p); }
};

/// One fit of the study: a model (axisymmetric or 3D) at a particles-per-cell count.
struct Fit {
  std::string model;
  int ppc = 2;
  double ns_per_particle_step = 0;
  double h_rel_min = 0, h_rel_max = 0;  ///< the study's cells, over R0
  Convergence L, D;                     ///< L_surface / L0, D_surface / D0
};

/// The bar the fit was measured on (V2) and the experiment's answer.
struct FitBar {
  double length = 0, radius = 0, speed = 0, density = 0, E = 0, nu = 0, A = 0, B = 0, n = 1;
  double c0 = 0, s = 0, gamma0 = 0, end_time = 0, L_exp = 0, D_exp = 0;
  std::string scheme;
  double cfl = 0, bulk_linear = 0, bulk_quadratic = 0;
};

double num(const toml::node_view<const toml::node>& v, const char* key) {
  const auto x = v[key].value<double>();
  if (!x) throw std::logic_error(std::string("taylor_fit.toml: missing ") + key);
  return *x;
}

Convergence convergence(const toml::node_view<const toml::node>& v) {
  return Convergence{num(v, "inf"), num(v, "a"), num(v, "p"), num(v, "rms")};
}

void read_fit(FitBar& bar, std::vector<Fit>& fits, std::string& source) {
  const toml::table doc = toml::parse(kTaylorFit);
  const toml::node_view<const toml::node> b = doc["bar"];
  bar = FitBar{num(b, "length"),
               num(b, "radius"),
               num(b, "speed"),
               num(b, "density"),
               num(b, "E"),
               num(b, "nu"),
               num(b, "A"),
               num(b, "B"),
               num(b, "n"),
               num(b, "c0"),
               num(b, "s"),
               num(b, "gamma0"),
               num(b, "end_time"),
               num(b, "L_exp"),
               num(b, "D_exp"),
               b["scheme"].value_or(""),
               num(b, "cfl"),
               num(b, "bulk_linear"),
               num(b, "bulk_quadratic")};
  source = doc["source"].value_or("");
  for (const toml::node& f : *doc["fits"].as_array()) {
    const toml::node_view<const toml::node> v{f};
    fits.push_back(Fit{v["model"].value_or(""), int(num(v, "particles_per_cell")),
                       num(v, "ns_per_particle_step"), num(v, "h_over_radius_min"),
                       num(v, "h_over_radius_max"), convergence(v["L"]), convergence(v["D"])});
  }
}

/// The bar of a scene: its body, radius, length, speed and which model it is; throws with the
/// reason when the scene is not a bar onto a wall.
struct SceneBar {
  int body = -1;
  double radius = 0, length = 0, speed = 0;
  std::string model;
};

[[noreturn]] void no_fit(const std::string& why) {
  throw InputError(kWhere, "no fit for this scene: " + why +
                               " (the trade study's fit holds for Taylor bars like V2: one "
                               "cylinder onto a rigid frictionless wall, examples/trade)");
}

SceneBar find_bar(const Scene& scene) {
  SceneBar bar;
  for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
    if (bar.body >= 0) no_fit("more than one body");
    bar.body = int(b);
  }
  const BodySpec& body = scene.bodies[bar.body];
  if (body.rigid || body.has_initial_fields() || body.particle_spacing > 0 || !scene.loads.empty())
    no_fit("the body is rigid, has initial fields, loads or its own particle spacing");
  if (!scene.grid.levels.empty() || scene.solver.type != SolverType::Explicit)
    no_fit("the fit is for the explicit solver on a uniform grid");
  if (!scene.solver.gravity.isZero(0)) no_fit("gravity");
  const int d = scene.dimension;
  const int ax = d == 3 ? 2 : 1;  // the bar's axis: z in 3D, y in axisymmetry
  const double base = d == 3 ? body.translate.z() : body.translate.y() - 0.5 * body.size.y();
  if (d == 3) {
    if (body.shape != ShapeKind::Cylinder || !body.rotate_deg.isZero(0) ||
        body.scale != Vec3::Ones())
      no_fit("the body is not an unrotated, unscaled cylinder along z");
    bar.radius = body.radius, bar.length = body.length, bar.model = "3d";
  } else {
    if (!scene.axisymmetric) no_fit("a 2D scene that is not axisymmetric");
    if (body.shape != ShapeKind::Box || body.rotate_deg.z() != 0 || body.scale != Vec3::Ones() ||
        std::abs(body.translate.x() - 0.5 * body.size.x()) > 1e-9 * body.size.x())
      no_fit("the body is not a rectangle from the axis (a cylinder in axisymmetry)");
    bar.radius = body.size.x(), bar.length = body.size.y(), bar.model = "axisymmetric";
  }
  Vec3 lateral = body.velocity;
  lateral[ax] = 0;
  if (!lateral.isZero(0) || body.velocity[ax] >= 0)
    no_fit("the bar does not move along its axis towards -" + std::string(1, "xyz"[ax]));
  if (scene.boundary.face[2 * ax] == BoundaryType::Free ||
      std::abs(base - scene.grid.domain_min[ax]) > 1e-6 * bar.length)
    no_fit(std::string("the bar's base does not touch a slip or fixed domain face ") + "xyz"[ax] +
           "_min");
  bar.speed = -body.velocity[ax];
  return bar;
}

/// Compares a dimensionless group of the scene with the fit's; no_fit when they differ by
/// more than 2%.
void similar(const char* name, double scene, double fit) {
  if (std::abs(scene - fit) <= 0.02 * std::abs(fit)) return;
  char b[200];
  std::snprintf(b, sizeof b, "%s = %.4g, the fit's bar (V2) %.4g (more than 2%% apart)", name,
                scene, fit);
  no_fit(b);
}

void check_similar(const Scene& scene, const SceneBar& bar, const FitBar& f) {
  const MaterialSpec& m = scene.materials[scene.bodies[bar.body].material];
  const StrengthSpec& st = m.strength;
  if (st.model == StrengthModel::Elastic || st.C != 0 || st.thermal())
    no_fit("the material's strength is not rate- and temperature-independent J2 hardening");
  if (m.eos.model != EosModel::MieGruneisen) no_fit("the equation of state is not Mie-Grueneisen");
  if (m.failure.enabled()) no_fit("the material fails");
  similar("length / radius", bar.length / bar.radius, f.length / f.radius);
  similar("density speed^2 / A", m.density * bar.speed * bar.speed / st.A,
          f.density * f.speed * f.speed / f.A);
  similar("B / A", st.B, st.A * f.B / f.A);
  similar("n", st.n, f.n);
  similar("E / A", m.youngs_modulus / st.A, f.E / f.A);
  similar("Poisson's ratio", m.poisson_ratio, f.nu);
  similar("speed / c0", bar.speed / m.eos.c0, f.speed / f.c0);
  similar("EOS s", m.eos.s, f.s);
  similar("EOS gamma0", m.eos.gamma0, f.gamma0);
  similar("bulk viscosity, linear", scene.solver.bulk_linear, f.bulk_linear);
  similar("bulk viscosity, quadratic", scene.solver.bulk_quadratic, f.bulk_quadratic);
  if (scene.solver.end_time * bar.speed / bar.length < 0.98 * f.end_time * f.speed / f.length)
    no_fit("the run ends before the bar comes to rest (end_time speed / length below V2's)");
}

/// Relative cost of a setting: particles times steps, up to a factor common to all settings.
double relative_cost(const std::string& model, double h, int ppc) {
  const double s = h / ppc;
  return (model == "3d" ? 1 / (s * s * s) : 1 / (s * s)) / h;
}

}  // namespace

double parse_target_error(const std::string& text) {
  std::string t = text;
  while (!t.empty() && (t.back() == ' ' || t.back() == '%')) t.pop_back();
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (t.empty() || *end != '\0' || !(v > 0) || v >= 100)
    throw InputError(
        kWhere,
        "expected a percentage above 0 and below 100 such as 2% or 0.5%, got '" + text + "'");
  return v / 100;
}

TargetProposal propose_for_target(const Scene& scene, double target) {
  FitBar f;
  std::vector<Fit> fits;
  TargetProposal p;
  read_fit(f, fits, p.fit_source);
  const SceneBar bar = find_bar(scene);
  check_similar(scene, bar, f);
  p.model = bar.model;
  p.target = target;
  const double l_exp = f.L_exp / f.length, d_exp = f.D_exp / (2 * f.radius);
  double best_cost = 0, floor = 1e300;
  std::string elsewhere;  // other models whose converged error is below the target
  for (const Fit& fit : fits) {
    const double fit_floor = std::max(std::abs(fit.L.inf / l_exp - 1) + 2 * fit.L.rms / l_exp,
                                      std::abs(fit.D.inf / d_exp - 1) + 2 * fit.D.rms / d_exp);
    if (fit.model != bar.model) {
      if (fit_floor < target) elsewhere += "; the " + fit.model + " model's fit reaches it";
      continue;
    }
    floor = std::min(floor, fit_floor);
    // Cells that tile the radius with whole particle spacings (h = ppc R0 / k), as in the study,
    // from the coarsest the study ran down to half its finest.
    for (int k = 2; k < 100000; ++k) {
      const double h_rel = double(fit.ppc) / k;
      if (h_rel > fit.h_rel_max * 1.001) continue;
      if (h_rel < 0.5 * fit.h_rel_min) break;
      // The prediction with twice the fit's scatter added must reach the target.
      const double eL = fit.L.at(h_rel) / l_exp - 1, eD = fit.D.at(h_rel) / d_exp - 1;
      const double mL = 2 * fit.L.rms / l_exp, mD = 2 * fit.D.rms / d_exp;
      const double e = std::max(std::abs(eL), std::abs(eD));
      if (std::max(std::abs(eL) + mL, std::abs(eD) + mD) > target) continue;
      const double h = h_rel * bar.radius, cost = relative_cost(bar.model, h, fit.ppc);
      if (p.cell_size == 0 || cost < best_cost) {
        best_cost = cost;
        p.cell_size = h, p.particles_per_cell = fit.ppc, p.predicted_error = e;
        p.predicted_L_error = eL, p.predicted_D_error = eD;
        p.margin_L = mL, p.margin_D = mD;
        p.ns_per_particle_step = fit.ns_per_particle_step;
        p.notes.clear();
        if (h_rel < fit.h_rel_min)
          p.notes.push_back("the cell is finer than the study's finest: the fit is extrapolated");
      }
      break;  // coarser cells of this fit are cheaper: the first that reaches the target wins
    }
  }
  if (floor > 1e299)
    throw InputError(kWhere,
                     "no fit for the " + bar.model +
                         " model of the bar in the trade study (examples/trade/taylor_fit.toml)");
  if (p.cell_size == 0) {
    char b[300];
    std::snprintf(
        b, sizeof b,
        "%.3g%% is not reached by the %s model at any cell down to half the study's "
        "finest: its converged error against the experiment is %.2f%% by the fit (with twice the "
        "scatter of the runs about it)",
        100 * target, bar.model.c_str(), 100 * floor);
    throw InputError(kWhere, b + elsewhere);
  }
  char b[64];
  std::snprintf(b, sizeof b, "grid.cell_size=%.6g mm", p.cell_size * 1e3);
  p.overrides.push_back(b);
  p.overrides.push_back("bodies." + scene.bodies[bar.body].name +
                        ".particles_per_cell=" + std::to_string(p.particles_per_cell));
  p.overrides.push_back("solver.scheme=" + f.scheme);
  std::snprintf(b, sizeof b, "solver.cfl=%g", f.cfl);
  p.overrides.push_back(b);
  return p;
}

void print_proposal(const TargetProposal& p, double particle_steps) {
  std::string sets;
  for (const std::string& s : p.overrides) sets += " --set " + s;
  std::fprintf(stderr, "  target error %.3g%% (%s model):%s\n", 100 * p.target, p.model.c_str(),
               sets.c_str());
  std::fprintf(stderr,
               "  predicted error %.2f%% against the experiment (L %+.2f%% +- %.2f%%, D %+.2f%% +- "
               "%.2f%%, on the surface); predicted cost %.3g particle-steps, %.3g s of one thread "
               "at %.0f ns a particle-step (measured by the study)\n",
               100 * p.predicted_error, 100 * p.predicted_L_error, 100 * p.margin_L,
               100 * p.predicted_D_error, 100 * p.margin_D, particle_steps,
               particle_steps * p.ns_per_particle_step * 1e-9, p.ns_per_particle_step);
  std::fprintf(stderr, "  fit: %s\n", p.fit_source.c_str());
  for (const std::string& n : p.notes) std::fprintf(stderr, "  note: %s\n", n.c_str());
}

}  // namespace mpm
