#include "mpm/run/run.hpp"

#include <omp.h>

#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "mpm/core/error.hpp"
#include "mpm/core/version.hpp"
#include "mpm/grid/lattice.hpp"
#include "mpm/solver/explicit/explicit_solver.hpp"
#include "mpm/solver/explicit/graded_solver.hpp"
#include "mpm/solver/explicit/sparse_solver.hpp"
#include "mpm/solver/implicit/implicit_solver.hpp"
#include "mpm/stream/stream.hpp"

namespace mpm {

const char* face_name(int face) {
  static const char* names[6] = {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max"};
  return names[face];
}

namespace {

/// Peak resident memory of this process (VmHWM), bytes; 0 when unknown.
double peak_memory() {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind("VmHWM:", 0) == 0) return 1024.0 * std::stod(line.substr(6));
  return 0;
}

std::atomic<int> g_signal{0};
extern "C" void on_signal(int sig) {
  g_signal = sig;
}

/// The model as read from mpm-prep's stream.
struct Model {
  std::string scene_text;
  Frame frame;
};

Model read_model(const std::string& path) {
  Model model;
  bool have_scene = false, have_frame = false;
  StreamVisitor v;
  v.scene = [&](const std::string& text) {
    model.scene_text = text;
    have_scene = true;
  };
  v.frame = [&](Frame&& f) {
    if (!have_frame) model.frame = std::move(f), have_frame = true;
  };
  const StreamSummary s = read_stream(path, v);
  const std::string name = path == "-" ? "stdin" : path;
  if (!s.damage.empty()) throw StreamError(name, s.damage);
  if (!have_scene)
    throw StreamError(name, "the stream holds no scene record: not a model from mpm-prep");
  if (!have_frame)
    throw StreamError(name, "the stream holds no particle frame: not a model from mpm-prep");
  if (s.ended && s.end_status != 0)
    throw StreamError(name, "the model was not completed by its producer (status " +
                                std::to_string(s.end_status) + ": " + s.end_message + ")");
  return model;
}

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
    for (const auto& c : scene.contacts) {
      const std::string pair = scene.bodies[c.body_a].name + "_" + scene.bodies[c.body_b].name;
      for (int a = 0; a < dim; ++a) add("contact_" + pair + "_" + "xyz"[a], "N");
    }
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
    const Balance& b = s.balance();
    // Extensive values as totals: per metre in plane strain, the whole ring in axisymmetry.
    const double k = factor_;
    std::vector<double> row = {double(s.steps()), s.time(),       dt,
                               k * b.kinetic,     k * b.internal, k * b.external_work,
                               k * b.removed,     k * b.total(),  k * b.leapfrog_total};
    for (int a = 0; a < dim_; ++a) row.push_back(k * b.momentum[a]);
    row.push_back(double(const_cast<Solver&>(s).particles().size()));
    for (int f : faces_) row.push_back(factor_ * s.face_force()[f]);
    for (int b : rigid_)
      for (int a = 0; a < dim_; ++a) row.push_back(factor_ * s.rigid_force()[b][a]);
    if constexpr (requires { s.contact_force(); })
      for (const Vec3& f : s.contact_force())
        for (int a = 0; a < dim_; ++a) row.push_back(factor_ * f[a]);
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
  void flush(StreamWriter& w) {
    if (block_.rows() == 0) return;
    w.write_history(block_);
    block_.values.clear();
  }
  std::size_t pending() const { return block_.rows(); }

 private:
  void add(const std::string& name, const std::string& unit) {
    block_.names.push_back(name);
    block_.units.push_back(unit);
  }
  int dim_;
  double factor_;
  bool implicit_;
  ImplicitWork last_;  ///< totals at the previous row
  std::vector<int> faces_, rigid_;
  HistoryBlock block_;
};

std::string run_info(const Scene& scene, const Lattice& lat, int threads) {
  std::ostringstream o;
  o << "tool = \"mpm-run\"\nversion = \"" << kVersion << "\"\nthreads = " << threads
    << "\ndimension = " << scene.dimension << "\n[lattice]\norigin = [" << lat.origin[0] << ", "
    << lat.origin[1] << ", " << lat.origin[2] << "]\nh = " << lat.h << "\ncells = [" << lat.cells[0]
    << ", " << lat.cells[1] << ", " << lat.cells[2] << "]\n";
  return o.str();
}

/// The next step (s): the solver's stable step, landing exactly on the next frame time and
/// avoiding a sliver step just before it.
template <class Solver>
double next_step(Solver& solver, double next_frame) {
  double dt = solver.stable_dt();
  const double to_frame = next_frame - solver.time();
  if (dt >= to_frame)
    dt = to_frame;
  else if (dt > 0.5 * to_frame)
    dt = 0.5 * to_frame;
  if (!(dt > 0) || !std::isfinite(dt))
    throw InstabilityError(solver.steps(), solver.time(), -1,
                           "the stable time step is " + std::to_string(dt) + " s");
  return dt;
}

/// The --stats report on stderr: kernel times, throughput, memory and the solver's work; the
/// time loop took loop_wall seconds.
template <class Solver>
void print_stats(Solver& solver, int threads, double loop_wall) {
  constexpr bool implicit = HasImplicitWork<Solver>;
  using GridT = std::remove_cvref_t<decltype(solver.grid())>;
  const double ps = solver.particle_steps();
  const double wall = solver.timers().total();
  std::fprintf(stderr, "\n%s", solver.timers().table(ps).c_str());
  std::string strategy = "colored";
  std::size_t work_bytes = 0;
  if constexpr (!implicit) {
    strategy = to_string(solver.strategy());
    work_bytes = solver.work_bytes();
  }
  std::fprintf(stderr,
               "\nstrategy %s, threads %d, particles %zu, steps %ld, sorts %ld, particle-steps "
               "%.4g, %.3f million particle-steps/s\n",
               strategy.c_str(), threads, solver.particles().size(), solver.steps(),
               solver.binning().sorts(), ps, wall > 0 ? ps / wall / 1e6 : 0.0);
  if constexpr (GridT::kGraded)
    std::fprintf(stderr, "graded grid: %d levels, %zu cells, %zu nodes; %ld particles split\n",
                 solver.grid().levels(), solver.grid().key_count(), solver.grid().nodes(),
                 solver.splits());
  const double peak = peak_memory();
  std::fprintf(
      stderr,
      "peak memory %.1f MB, %.0f bytes per particle (all of the process: particles, "
      "grid window, sort scratch, the model as read); particle columns %zu bytes, grid "
      "window %zu nodes%s\n",
      peak / 1e6, peak / double(std::max<std::size_t>(1, solver.particles().size())),
      solver.particles().element_bytes(), solver.grid().nodes(),
      implicit ? ""
               : (", solver work arrays " + std::to_string(work_bytes / 1000000) + " MB").c_str());
  if constexpr (implicit) {
    const ImplicitWork& w = solver.work();
    std::fprintf(stderr,
                 "implicit: explicit dt %.6g s, steps %ld, newton %ld, krylov %ld, residual "
                 "evaluations %ld, line-search cuts %ld, step cuts %ld (lagrangian %ld), wall "
                 "%.4f s (time loop)\n",
                 solver.explicit_dt(), w.steps, w.newton, w.krylov, w.evaluations,
                 w.line_search_cuts, w.step_cuts, w.lagrangian_cuts, loop_wall);
  } else {
    std::fprintf(stderr, "explicit: steps %ld, wall %.4f s (time loop)\n", solver.steps(),
                 loop_wall);
  }
}

template <class Solver>
int run_solver(const RunOptions& opt, const Scene& scene, const Lattice& lattice, Solver& solver) {
  constexpr bool implicit = HasImplicitWork<Solver>;
  using GridT = std::remove_cvref_t<decltype(solver.grid())>;
  const int threads = omp_get_max_threads();
  StreamWriter out(opt.output);
  out.write_text(RecordType::Scene, scene.toml);
  out.write_text(RecordType::Info, run_info(scene, lattice, threads));
  // Graded grids: a GRID record at the start and whenever the grid was rebuilt.
  long grid_revision = -1;
  auto emit_grid = [&]() {
    if constexpr (GridT::kGraded) {
      if (solver.grid().revision() == grid_revision) return;
      grid_revision = solver.grid().revision();
      out.write_record(RecordType::Grid,
                       encode_grid(solver.grid().mesh(solver.steps(), solver.time())));
    }
  };
  emit_grid();

  const OutputSpec& o = scene.output;
  const double end = scene.solver.end_time;
  KernelTimers& timers = solver.timers();
  const int t_output = timers.id("output");

  History history(Solver::D, scene, implicit);
  auto emit_frame = [&](std::uint32_t flags) {
    ScopedTimer timer(timers, t_output);
    history.flush(out);
    emit_grid();
    Frame f;
    f.step = solver.steps();
    f.time = solver.time();
    f.flags = flags;
    std::swap(f.columns, solver.particles());
    try {
      out.write_frame(f, o.fields, o.precision);
    } catch (...) {
      std::swap(f.columns, solver.particles());
      throw;
    }
    std::swap(f.columns, solver.particles());
  };

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  history.record(solver, 0.0);
  emit_frame(0);

  Progress progress(opt.progress, end);
  int frame = 1;
  double next_frame = end * frame / o.frames;
  double next_history = o.history_interval;
  int status = kExitOk;
  std::string message;
  const long max_steps = scene.solver.max_steps;
  const double loop_start = omp_get_wtime();
  try {
    while (solver.time() < end * (1 - 1e-12)) {
      if (g_signal) {
        status = 128 + g_signal;
        message = "interrupted by signal " + std::to_string(int(g_signal)) +
                  " at t = " + std::to_string(solver.time()) +
                  " s; the last frame is the state then";
        break;
      }
      if (max_steps > 0 && solver.steps() >= max_steps) {
        message = "stopped at solver.max_steps = " + std::to_string(max_steps);
        break;
      }
      double dt = next_step(solver, next_frame);
      solver.step(dt);
      if constexpr (implicit) dt = solver.last_dt();  // cut when Newton failed
      if (solver.time() >= next_history * (1 - 1e-12) || o.history_interval <= 0) {
        history.record(solver, dt);
        next_history += o.history_interval;
        if (history.pending() >= 4096) history.flush(out);
      }
      if (solver.time() >= next_frame * (1 - 1e-12)) {
        if (history.pending() == 0 || o.history_interval > 0) history.record(solver, dt);
        emit_frame(frame == o.frames ? std::uint32_t(kFrameFinal) : 0u);
        ++frame;
        next_frame = frame <= o.frames ? end * frame / o.frames : end;
      }
      progress.update(solver.time(), solver.steps());
    }
    progress.done(solver.time(), solver.steps());
    if (status != kExitOk || !message.empty()) {
      history.record(solver, 0.0);
      emit_frame(kFrameFinal);
    }
    if (message.empty())
      message = "completed " + std::to_string(solver.steps()) +
                " steps to t = " + std::to_string(solver.time()) + " s";
  } catch (const InstabilityError& e) {
    progress.done(solver.time(), solver.steps());
    status = kExitUnstable;
    message = e.what();
  }
  const double loop_wall = omp_get_wtime() - loop_start;  // the time loop, output included
  history.flush(out);
  out.write_end(status, message);
  out.close();
  if (status == kExitUnstable) {
    std::fprintf(stderr,
                 "mpm-run: error: %s\nmpm-run: the %d frame(s) written before stay valid "
                 "(last at t = %g s)\n",
                 message.c_str(), frame, frame > 1 ? end * (frame - 1) / o.frames : 0.0);
  } else {
    std::fprintf(stderr, "mpm-run: %s\n", message.c_str());
  }
  if (solver.removed_particles() > 0)
    std::fprintf(stderr, "mpm-run: %zu particles left the domain and were removed\n",
                 solver.removed_particles());
  if (opt.stats) print_stats(solver, threads, loop_wall);
  return status;
}

template <int D>
int run(const RunOptions& opt, const Scene& scene, const Lattice& lattice, Frame& model) {
  const bool graded = !scene.grid.levels.empty();  // mesh grading (004, section 3)
  if (scene.solver.type == SolverType::Implicit) {
    if (graded)
      throw InputError("grid.levels",
                       "the implicit solver runs on a uniform grid; remove the "
                       "[[grid.levels]] boxes or use solver.type = \"explicit\"");
    if (scene.grid.sparse)
      throw InputError("grid.sparse",
                       "the implicit solver runs on the dense grid; remove "
                       "grid.sparse or use solver.type = \"explicit\"");
    ImplicitSolver<UniformGrid<D>> solver(scene, UniformGrid<D>(lattice, scene.boundary),
                                          model.columns);
    return run_solver(opt, scene, lattice, solver);
  }
  const ScatterStrategy strategy = parse_strategy(opt.strategy, "--strategy");
  if (opt.deterministic && strategy != ScatterStrategy::Colored)
    throw InputError("--deterministic",
                     "only the colored strategy gives results independent of the thread count "
                     "(it is the default); drop --strategy " +
                         opt.strategy);
  if (graded) {
    if (strategy == ScatterStrategy::Patch)
      throw InputError("--strategy",
                       "the patch strategy needs a uniform grid; this scene has "
                       "[[grid.levels]] (use colored, lr-slabs or array-expansion)");
    ExplicitSolver<GradedGrid<D>> solver(scene, GradedGrid<D>(lattice, scene), model.columns,
                                         strategy);
    return run_solver(opt, scene, lattice, solver);
  }
  if (scene.grid.sparse) {
    if (strategy == ScatterStrategy::Patch)
      throw InputError("--strategy",
                       "the patch strategy cuts the dense window into slabs of "
                       "nodes; with grid.sparse use colored, lr-slabs or "
                       "array-expansion");
    ExplicitSolver<SparseGrid<D>> solver(scene, SparseGrid<D>(lattice, scene.boundary),
                                         model.columns, strategy);
    return run_solver(opt, scene, lattice, solver);
  }
  UniformSolver<D> solver(scene, UniformGrid<D>(lattice, scene.boundary), model.columns, strategy);
  return run_solver(opt, scene, lattice, solver);
}

}  // namespace

int run_model(const RunOptions& opt) {
  if (opt.threads > 0) omp_set_num_threads(opt.threads);
  for (const auto& kv : opt.overrides)
    if (kv.rfind("bodies", 0) == 0)
      throw InputError("--set " + kv.substr(0, kv.find('=')),
                       "bodies are fixed once mpm-prep has made the particles; pass this "
                       "override to mpm-prep instead");
  Model model = read_model(opt.input);
  const std::string name = (opt.input == "-" ? std::string("stdin") : opt.input) + " (scene)";
  const Scene scene = parse_scene(model.scene_text, name, "", opt.overrides);
  const Lattice lattice = make_lattice(scene);
  if (scene.dimension == 3) return run<3>(opt, scene, lattice, model.frame);
  return run<2>(opt, scene, lattice, model.frame);
}

}  // namespace mpm
