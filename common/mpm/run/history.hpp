#pragma once
/// The history mpm-run writes: one row per time of energies, momentum, wall and rigid-body
/// forces, the implicit solver's work and, per body, mass, momentum and energies.
#include <string>
#include <vector>

#include "mpm/core/columns.hpp"
#include "mpm/core/comm.hpp"
#include "mpm/scene/particles.hpp"
#include "mpm/scene/scene.hpp"
#include "mpm/solver/implicit/implicit_solver.hpp"
#include "mpm/stream/stream.hpp"

namespace mpm {

const char* face_name(int face);

/// True for a solver with the implicit one's work counters.
template <class Solver>
concept HasImplicitWork = requires(const Solver& s) {
  s.work();
  s.explicit_dt();
};

/// History rows, written as HIST records at each frame and every few thousand rows.
class History {
 public:
  History(int dim, const Scene& scene, bool implicit)
      : dim_(dim), factor_(scene.measure_factor()), implicit_(implicit) {
    const BoundarySpec& bc = scene.boundary;
    add("step", "-");
    add("time", "s");
    add("dt", "s");
    add("kinetic", "J");
    add("internal", "J");
    add("external_work", "J");
    add("removed", "J");
    add("total", "J");
    add("leapfrog_total", "J");
    const char* axes[3] = {"momentum_x", "momentum_y", "momentum_z"};
    for (int a = 0; a < dim; ++a) add(axes[a], "kg m/s");
    add("particles", "-");
    if (scene.solver.on_exit == OnExit::Remove) {  // what left, so that the totals close
      removed_ = true;
      add("removed_mass", "kg");
      const char* out[3] = {"removed_momentum_x", "removed_momentum_y", "removed_momentum_z"};
      for (int a = 0; a < dim; ++a) add(out[a], "kg m/s");
    }
    for (int f = 0; f < 2 * dim; ++f)
      if (bc.face[f] != BoundaryType::Free) {
        faces_.push_back(f);
        add(std::string("force_") + face_name(f), "N");
      }
    for (std::size_t b = 0; b < scene.bodies.size(); ++b)
      if (scene.bodies[b].rigid) {
        rigid_.push_back(int(b));
        for (int a = 0; a < dim; ++a) add("force_" + scene.bodies[b].name + "_" + "xyz"[a], "N");
      }
    for (const auto& c : scene.contacts) {  // force on the first body of each pair
      const std::string pair = scene.bodies[c.body_a].name + "_" + scene.bodies[c.body_b].name;
      for (int a = 0; a < dim; ++a) add("contact_" + pair + "_" + "xyz"[a], "N");
    }
    if (!scene.rebars.empty()) {  // the rebar's elements eroded so far
      rebar_ = true;
      add("rebar_eroded", "-");
    }
    add_body_columns(scene);
    if (implicit_) {
      // Work of the implicit solver since the previous row, then totals since t = 0.
      add("dt_multiple", "-");
      add("newton", "-");
      add("krylov", "-");
      add("residual_evals", "-");
      add("line_search_cuts", "-");
      add("step_cuts", "-");
      add("newton_total", "-");
      add("krylov_total", "-");
      add("residual_evals_total", "-");
    }
  }
  template <class Solver>
  void record(const Solver& s, double dt) {
    if (s.steps() == last_step_) return;  // one row per time
    last_step_ = s.steps();
    const Balance& b = s.balance();
    // Extensive values as totals: per metre in plane strain, the whole ring in axisymmetry.
    const double k = factor_;
    std::vector<double> row = {double(s.steps()), s.time(),       dt,
                               k * b.kinetic,     k * b.internal, k * b.external_work,
                               k * b.removed,     k * b.total(),  k * b.leapfrog_total};
    for (int a = 0; a < dim_; ++a) row.push_back(k * b.momentum[a]);
    row.push_back(double(s.particle_count()));  // every rank's under mpirun
    if (removed_) {
      row.push_back(k * b.removed_mass);
      for (int a = 0; a < dim_; ++a) row.push_back(k * b.removed_momentum[a]);
    }
    for (int f : faces_) row.push_back(factor_ * s.face_force()[f]);
    for (int b : rigid_)
      for (int a = 0; a < dim_; ++a) row.push_back(factor_ * s.rigid_force()[b][a]);
    if constexpr (requires { s.contact_force(); })
      for (const Vec3& f : s.contact_force())
        for (int a = 0; a < dim_; ++a) row.push_back(factor_ * f[a]);
    if constexpr (requires { s.eroded_elements(); })
      if (rebar_) row.push_back(double(s.eroded_elements()));
    if (!bodies_.empty()) body_values(const_cast<Solver&>(s).particles(), row);
    if constexpr (HasImplicitWork<Solver>) {
      const ImplicitWork& w = s.work();
      row.insert(row.end(),
                 {dt / s.explicit_dt(), double(w.newton - last_.newton),
                  double(w.krylov - last_.krylov), double(w.evaluations - last_.evaluations),
                  double(w.line_search_cuts - last_.line_search_cuts),
                  double(w.step_cuts - last_.step_cuts), double(w.newton), double(w.krylov),
                  double(w.evaluations)});
      last_ = w;
    }
    block_.values.insert(block_.values.end(), row.begin(), row.end());
  }
  /// Checkpoints: the implicit solver's work totals at the last row (its rows give the work
  /// since the row before).
  void save(StateValues& s) const {
    if (implicit_)
      ImplicitWork::each(last_, [&](const std::string& n, long v) { s.set("history_" + n, v); });
  }
  void restore(const StateValues& s) {
    if (implicit_)
      ImplicitWork::each(last_,
                         [&](const std::string& n, long& v) { v = long(s.get("history_" + n)); });
  }
  void flush(StreamWriter& w) {
    if (block_.rows() == 0) return;
    w.write_history(block_);
    block_.values.clear();
  }
  std::size_t pending() const { return block_.rows(); }
  /// Drops the pending rows (under mpirun, on the ranks that do not write the stream).
  void discard() { block_.values.clear(); }

 private:
  void add(const std::string& name, const std::string& unit) {
    block_.names.push_back(name);
    block_.units.push_back(unit);
  }
  /// The per-body columns (output.body_history): mass, momentum, kinetic and internal energy
  /// of each deformable body, named by body.
  void add_body_columns(const Scene& scene) {
    std::vector<int> deformable;
    for (std::size_t b = 0; b < scene.bodies.size(); ++b)
      if (!scene.bodies[b].rigid) deformable.push_back(int(b));
    const int n = int(deformable.size());
    if (!scene.output.body_history.value_or(n >= 2 && n <= OutputSpec::kBodyHistoryAuto)) return;
    bodies_ = deformable;
    slot_.assign(scene.bodies.size(), -1);
    for (std::size_t k = 0; k < bodies_.size(); ++k) {
      const std::string& name = scene.bodies[bodies_[k]].name;
      slot_[bodies_[k]] = int(k);
      add("mass_" + name, "kg");
      for (int a = 0; a < dim_; ++a) add("momentum_" + name + "_" + "xyz"[a], "kg m/s");
      add("kinetic_" + name, "J");
      add("internal_" + name, "J");
    }
  }
  /// Appends each body's mass, momentum, kinetic and internal energy (totals, as the other
  /// columns) to `row`: one pass over the particles, only at history rows.
  void body_values(const ColumnStore& particles, std::vector<double>& row) const {
    const int per = dim_ + 3;
    std::vector<double> sum(bodies_.size() * per, 0.0);
    const std::size_t n = particles.size();
    const BodyIds body(particles.find(col::body));
    const double* m = particles.get<double>(col::m);
    const auto* v = reinterpret_cast<const double*>(particles.at(col::v).data());  // dim_ a row
    const double* e = particles.get<double>(col::e);  // nullptr without the column
    for (std::size_t i = 0; i < n; ++i) {
      const int k = slot_[body[i]];
      if (k < 0) continue;
      double* out = &sum[std::size_t(k) * per];
      double v2 = 0;
      for (int a = 0; a < dim_; ++a) {
        const double va = v[i * dim_ + a];
        out[1 + a] += m[i] * va;
        v2 += va * va;
      }
      out[0] += m[i];
      out[dim_ + 1] += 0.5 * m[i] * v2;
      if (e) out[dim_ + 2] += m[i] * e[i];
    }
    Comm::world().sum(sum.data(), int(sum.size()));  // every rank's particles, in rank order
    for (double x : sum) row.push_back(factor_ * x);
  }
  int dim_;
  double factor_;
  bool implicit_;
  ImplicitWork last_;     ///< totals at the previous row
  long last_step_ = -1;   ///< step of the last row
  bool removed_ = false;  ///< columns of what left the domain (solver.on_exit = "remove")
  bool rebar_ = false;    ///< the column of the rebar's eroded elements
  std::vector<int> faces_, rigid_;
  std::vector<int> bodies_;  ///< deformable bodies with history columns (output.body_history)
  std::vector<int> slot_;    ///< by body: its index in bodies_, -1 when it has no columns
  HistoryBlock block_;
};

}  // namespace mpm
