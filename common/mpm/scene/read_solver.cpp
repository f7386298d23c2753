// The scene parser's [solver] (explicit, or implicit with [solver.implicit]) and [output].
#include <climits>
#include <string>

#include "mpm/scene/read_sections.hpp"

namespace mpm::scene_toml {

namespace {

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

}  // namespace

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
  v.scheme = r.choice<Scheme>("scheme",
                              {{"USF", Scheme::USF},
                               {"USL", Scheme::USL},
                               {"MUSL", Scheme::MUSL},
                               {"APIC", Scheme::APIC}},
                              true)
                 .value_or(Scheme::MUSL);
  if (v.scheme == Scheme::APIC && !s.grid.levels.empty())
    r.fail("scheme",
           "\"APIC\" runs on uniform and sparse grids; a graded grid (grid.levels) takes "
           "\"USF\", \"USL\" or \"MUSL\"");
  if (v.scheme == Scheme::APIC && !s.contacts.empty())
    r.fail("scheme",
           "\"APIC\" does not yet carry the affine momentum into the bodies' own fields of "
           "[[contact]]; use \"MUSL\" (or drop the [[contact]] entries)");
  if (v.type == SolverType::Implicit && s.grid.shape == GridShape::Bspline)
    r.fail("type",
           "the implicit solver runs on linear shape functions; remove grid.shape = "
           "\"bspline\" or use solver.type = \"explicit\"");
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
  o.body_history = r.boolean("body_history");
  if (r.get("checkpoint")) {
    auto t = r.table("checkpoint", {"time", "wall"});
    o.checkpoint_time = t->quantity("time", dim::time, Bound::Positive).value_or(0.0);
    o.checkpoint_wall = t->quantity("wall", dim::time, Bound::Positive).value_or(0.0);
    t->finish();
    if (o.checkpoint_time == 0 && o.checkpoint_wall == 0)
      r.fail("checkpoint",
             "expected the time between checkpoints: { time = \"10 us\" } of simulated time, "
             "{ wall = \"1800 s\" } of wall-clock time, or both");
  }
  r.finish();
}

}  // namespace mpm::scene_toml
