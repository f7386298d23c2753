#include "mpm/run/run.hpp"

#include <omp.h>
#include <toml++/toml.h>

#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>

#include "mpm/core/cli.hpp"
#include "mpm/core/comm.hpp"
#include "mpm/core/error.hpp"
#include "mpm/core/units.hpp"
#include "mpm/core/version.hpp"
#include "mpm/grid/bspline_grid.hpp"
#include "mpm/grid/lattice.hpp"
#include "mpm/run/extremes.hpp"
#include "mpm/run/history.hpp"
#include "mpm/run/restart.hpp"
#include "mpm/scene/particles.hpp"
#include "mpm/solver/explicit/explicit_solver.hpp"
#include "mpm/solver/explicit/graded_solver.hpp"
#include "mpm/solver/explicit/sparse_solver.hpp"
#include "mpm/solver/implicit/implicit_solver.hpp"
#include "mpm/solver/ranks.hpp"
#include "mpm/stream/stream.hpp"

namespace mpm {

const char* face_name(int face) {
  static const char* names[6] = {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max"};
  return names[face];
}

namespace {

/// The particles that left the domain since the last ESCP record (before the next frame or
/// checkpoint), as an ESCP record stamped with the step and time (s); the log is emptied.
void write_escapes(StreamWriter& out, EscapeLog& log, long step, double time) {
  if (log.size() == 0) return;
  Frame e;
  e.step = step;
  e.time = time;
  std::swap(e.columns, log.columns());
  try {
    out.write_escapes(e);
  } catch (...) {
    std::swap(e.columns, log.columns());
    throw;
  }
  std::swap(e.columns, log.columns());
  log.clear();
}

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
  Frame rebar;  ///< the REBR record: the rebar's elements (no columns without rebar)
};

/// Refuses, before the particles are read, a model whose run would need more than `limit`
/// bytes: its particles (from mpm-prep's INFO record) times a run's bytes a particle and the
/// model's, and a grid window of at most a node a particle and at most the domain.
void check_model_memory(const std::string& name, const std::string& scene_text,
                        const std::string& info, const RunOptions& opt) {
  const double limit = opt.max_memory > 0 ? opt.max_memory : machine_memory();
  if (!(limit > 0)) return;
  double particles = 0;
  try {
    const toml::table t = toml::parse(info);
    if (const auto* bodies = t["bodies"].as_array())
      for (const auto& b : *bodies)
        if (const auto* table = b.as_table()) particles += (*table)["particles"].value_or(0.0);
  } catch (const toml::parse_error&) {
    return;  // not mpm-prep's info: the frame's own checks apply
  }
  const Scene scene = parse_scene(scene_text, name + " (scene)", "", opt.overrides);
  double nodes = 1;
  if (scene.grid.domain_given) {
    const Lattice lat = make_lattice(scene);
    for (int a = 0; a < scene.dimension; ++a) nodes *= lat.cells[a] + 1.0;
  }
  const int d = scene.dimension;
  const double model_bytes = 4 + 1 + 1 + 2 * d * 8 + 8 + 8;  // the model's columns as read
  const double need = particles * (run_particle_bytes(scene) + model_bytes) +
                      std::min(nodes, particles) * grid_node_bytes(d);
  if (need > limit)
    throw InputError(name, "the model holds " + format_count(particles) +
                               " particles; running it would need about " + format_bytes(need) +
                               " of memory, more than the limit of " + format_bytes(limit) +
                               " (--max-memory; by default the machine's memory): run it on a "
                               "larger machine, or make a coarser model with mpm-prep");
}

Model read_model(const RunOptions& opt) {
  const std::string& path = opt.input;
  Model model;
  bool have_scene = false, have_frame = false;
  StreamVisitor v;
  v.scene = [&](const std::string& text) {
    model.scene_text = text;
    have_scene = true;
  };
  v.info = [&](const std::string& text) {
    if (!have_frame && text.find("tool = \"mpm-run\"") != std::string::npos)
      throw InputError(path == "-" ? "stdin" : path,
                       "this is a result from mpm-run, not a model: to continue it from its "
                       "last checkpoint use mpm-run --restart " +
                           path +
                           "; to run again from t = 0, run mpm-run on the model from "
                           "mpm-prep");
    if (have_scene && !have_frame)
      check_model_memory(path == "-" ? "stdin" : path, model.scene_text, text, opt);
  };
  v.frame = [&](Frame&& f) {
    if (!have_frame) model.frame = std::move(f), have_frame = true;
  };
  v.rebar = [&](Frame&& f) {
    if (model.rebar.columns.columns().empty()) model.rebar = std::move(f);
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

std::string run_info(const Scene& scene, const Lattice& lat, int threads) {
  std::ostringstream o;
  o << "tool = \"mpm-run\"\nversion = \"" << kVersion << "\"\nthreads = " << threads
    << "\nranks = " << Comm::world().size() << "\ndimension = " << scene.dimension
    << "\n[lattice]\norigin = [" << lat.origin[0] << ", " << lat.origin[1] << ", " << lat.origin[2]
    << "]\nh = " << lat.h << "\ncells = [" << lat.cells[0] << ", " << lat.cells[1] << ", "
    << lat.cells[2] << "]\n";
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
               strategy.c_str(), threads, solver.particle_count(), solver.steps(),
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

/// A result stream continued from its last checkpoint (mpm-run --restart).
struct Restart {
  RestartScan scan;
  Checkpoint checkpoint;
  Frame rebar;  ///< the rebar's elements at the checkpoint (the REBR record before it)
};

/// Steps a stop by SIGINT or SIGTERM waits for the particles' next re-sort, so that the
/// checkpoint it writes continues the run bitwise (CheckpointClock::kMaxWait for the same).
constexpr int kSignalWait = 20;

/// The time loop of mpm-run: steps the solver to the end time, writes frames, history rows
/// and checkpoints to the result stream, and stops cleanly on SIGINT or SIGTERM.
template <class Solver>
class TimeLoop {
  static constexpr bool kImplicit = HasImplicitWork<Solver>;
  using GridT = std::remove_cvref_t<decltype(std::declval<Solver&>().grid())>;

 public:
  TimeLoop(const RunOptions& opt, const Scene& scene, const Lattice& lattice, Solver& solver,
           const Restart* restart, ColumnStore* rebar)
      : opt_(opt),
        o_(scene.output),
        end_(scene.solver.end_time),
        solver_(solver),
        restart_(restart),
        rebar_(rebar),
        history_(Solver::D, scene, kImplicit),
        extremes_(scene),
        checkpoint_(scene.output, solver.time()),
        t_output_(solver.timers().id("output")) {
    if (restart) {
      out_ = std::make_unique<StreamWriter>(opt.output, opt.restart, restart->scan.keep);
      const StateValues& s = restart->checkpoint.state;
      frame_ = int(s.get("frame"));
      next_history_ = s.get("next_history");
      history_.restore(s);
      if constexpr (GridT::kGraded) grid_revision_ = long(s.get("grid_revision_written"));
      checkpoint_.restore(s);
    } else if (comm_.root()) {  // under mpirun the root writes the stream
      out_ = std::make_unique<StreamWriter>(opt.output,
                                            rebar ? kStreamVersionMinor : kStreamMinorWithoutRebar);
      out_->write_text(RecordType::Scene, scene.toml);
      out_->write_text(RecordType::Info, run_info(scene, lattice, omp_get_max_threads()));
    }
    if (!restart) next_history_ = o_.history_interval;
  }

  int operator()();

 private:
  double next_frame() const { return frame_ <= o_.frames ? end_ * frame_ / o_.frames : end_; }
  /// Graded grids: a GRID record at the start and whenever the grid was rebuilt.
  void emit_grid() {
    if constexpr (GridT::kGraded) {
      if (solver_.grid().revision() == grid_revision_) return;
      grid_revision_ = solver_.grid().revision();
      out_->write_record(RecordType::Grid,
                         encode_grid(solver_.grid().mesh(solver_.steps(), solver_.time())));
    }
  }
  /// The particles as a frame, or in a checkpoint, written without copying them; under
  /// mpirun every rank's, gathered at the root in particle-id order into gathered_ (which
  /// emit_frame samples for the material extremes, then frees).
  template <class Write>
  void write_particles(std::uint32_t flags, Write&& write) {
    Frame f;
    f.step = solver_.steps();
    f.time = solver_.time();
    f.flags = flags;
    if (comm_.parallel()) {
      gather_by_id(comm_, solver_.particles(), gathered_);
      if (!comm_.root()) return;
    }
    ColumnStore& cols = comm_.parallel() ? gathered_ : solver_.particles();
    std::swap(f.columns, cols);
    try {
      write(f);
    } catch (...) {
      std::swap(f.columns, cols);
      throw;
    }
    std::swap(f.columns, cols);
  }
  void emit_frame(std::uint32_t flags) {
    ScopedTimer timer(solver_.timers(), t_output_);
    flush_history();
    emit_escapes();
    emit_grid();
    write_particles(flags, [&](const Frame& f) { out_->write_frame(f, o_.fields, o_.precision); });
    if (rebar_) write_rebar(flags);  // the elements' state at the frame (after it)
    if (comm_.root())                // one process's particles, or every rank's gathered there
      extremes_.sample(comm_.parallel() ? gathered_ : solver_.particles(), solver_.time());
    gathered_ = ColumnStore();
  }
  /// History rows to the stream (the root's; the other ranks computed the same rows).
  void flush_history() {
    if (out_)
      history_.flush(*out_);
    else
      history_.discard();
  }
  /// The particles that left the domain since the last ESCP record; under mpirun every
  /// rank's, gathered at the root.
  void emit_escapes() {
    EscapeLog& log = solver_.escapes();
    if (comm_.parallel()) {
      ColumnStore all;
      gather_by_id(comm_, log.columns(), all);
      log.clear();
      if (!comm_.root()) return;
      if (all.size() > 0) std::swap(log.columns(), all);
    }
    write_escapes(*out_, log, solver_.steps(), solver_.time());
  }
  /// A REBR record: the rebar's elements now, written without copying them.
  void write_rebar(std::uint32_t flags) {
    Frame e;
    e.step = solver_.steps();
    e.time = solver_.time();
    e.flags = flags;
    std::swap(e.columns, *rebar_);
    try {
      out_->write_rebar(e);
    } catch (...) {
      std::swap(e.columns, *rebar_);
      throw;
    }
    std::swap(e.columns, *rebar_);
  }
  /// A CHKP record: the particles in cell order (settle) with the state the columns do not
  /// hold; the history rows before it are flushed first, so the stream up to it is complete.
  void write_checkpoint() {
    ScopedTimer timer(solver_.timers(), t_output_);
    solver_.settle();
    flush_history();
    emit_escapes();
    StateValues s;
    solver_.save_state(s);
    s.set("frame", frame_);
    s.set("next_history", next_history_);
    history_.save(s);
    if constexpr (GridT::kGraded) s.set("grid_revision_written", double(grid_revision_));
    checkpoint_.save(s);
    if (rebar_) write_rebar(0);  // the elements' state, before the checkpoint it goes with
    write_particles(0, [&](const Frame& f) { out_->write_checkpoint(s, f); });
    checkpoint_.written();
  }
  /// Whether to stop for a signal now: after a checkpoint, which the explicit solver writes
  /// once the particles are due for a re-sort (at most kSignalWait steps on), the implicit one
  /// at once (as advance() does).
  bool stop_for_signal() {
    if (comm_.parallel()) g_signal = int(comm_.max(g_signal));  // every rank stops at once
    if (!g_signal) return false;
    if (!kImplicit && !solver_.sort_pending() && ++signal_wait_ <= kSignalWait) return false;
    const bool on_schedule = kImplicit || solver_.sort_pending();
    write_checkpoint();
    status_ = 128 + g_signal;
    message_ = "interrupted by signal " + std::to_string(int(g_signal)) +
               " at t = " + std::to_string(solver_.time()) + " s; the last frame is the state then";
    if (!on_schedule)
      message_ += " (the particles were not due for a re-sort within " +
                  std::to_string(kSignalWait) +
                  " steps, so the checkpoint re-sorted them: a continued run differs from an "
                  "uninterrupted one at round-off)";
    message_ += opt_.output == "-"
                    ? "; the stream holds a checkpoint of it: saved to a file, it continues "
                      "with mpm-run --restart FILE"
                    : "; continue with: mpm-run --restart " + opt_.output;
    return true;
  }
  /// One step and what follows it: history rows, frames, checkpoints.
  void advance();
  void report(double loop_wall) const;
  /// --stats under mpirun: each rank's particles, shared nodes, and what it sent (collective).
  std::string rank_stats() const;

  const Comm& comm_ = Comm::world();
  const RunOptions& opt_;
  const OutputSpec& o_;
  const double end_;
  Solver& solver_;
  const Restart* restart_;
  ColumnStore* rebar_;    ///< the rebar's element table, or null
  ColumnStore gathered_;  ///< under mpirun, at the root: every rank's particles at the last frame
  std::unique_ptr<StreamWriter> out_;
  History history_;
  MaterialExtremes extremes_;  ///< sampled at each frame, reported at the end
  CheckpointClock checkpoint_;
  int t_output_;
  long grid_revision_ = -1;
  int frame_ = 1;  ///< index of the next frame; frame k is at end_time k / frames
  double next_history_ = 0;
  int signal_wait_ = 0;
  int status_ = kExitOk;
  std::string message_;
};

template <class Solver>
void TimeLoop<Solver>::advance() {
  const double pace = solver_.stable_dt();  // the step taken when no frame time is near
  double dt = next_step(solver_, next_frame());
  if constexpr (kImplicit)
    solver_.step(dt);
  else
    solver_.step(dt, pace);  // the leapfrog energy evaluated at the pace, not the cut step
  if constexpr (kImplicit) dt = solver_.last_dt();  // cut when Newton failed
  if (solver_.time() >= next_history_ * (1 - 1e-12) || o_.history_interval <= 0) {
    history_.record(solver_, dt);
    next_history_ += o_.history_interval;
    if (history_.pending() >= 4096) flush_history();
  }
  if (solver_.time() >= next_frame() * (1 - 1e-12)) {
    history_.record(solver_, dt);  // a row at each frame time (one: record skips a repeat)
    emit_frame(frame_ == o_.frames ? std::uint32_t(kFrameFinal) : 0u);
    ++frame_;
  }
  checkpoint_.tick(solver_.time());
  // The explicit solver waits for its own re-sort (the frames stay bitwise those of a run
  // without checkpoints); the implicit one's steps are long, and a checkpoint drops its warm
  // start anyway (ImplicitSolver::settle): it writes at once.
  if (solver_.time() < end_ * (1 - 1e-12) &&
      comm_.any(checkpoint_.write_now(kImplicit || solver_.sort_pending())))
    write_checkpoint();
}

template <class Solver>
int TimeLoop<Solver>::operator()() {
  if (!restart_) {
    emit_grid();
    history_.record(solver_, 0.0);
    emit_frame(0);
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  Progress progress(comm_.root() ? opt_.progress : ProgressMode::None, end_);
  const long max_steps = solver_.scene().solver.max_steps;
  const double loop_start = omp_get_wtime();
  try {
    while (solver_.time() < end_ * (1 - 1e-12)) {
      if (stop_for_signal()) break;
      if (max_steps > 0 && solver_.steps() >= max_steps) {
        message_ = "stopped at solver.max_steps = " + std::to_string(max_steps);
        break;
      }
      advance();
      progress.update(solver_.time(), solver_.steps());
    }
    progress.done(solver_.time(), solver_.steps());
    if (status_ != kExitOk || !message_.empty()) {
      history_.record(solver_, 0.0);
      emit_frame(kFrameFinal);
    }
    if (message_.empty())
      message_ = "completed " + std::to_string(solver_.steps()) +
                 " steps to t = " + std::to_string(solver_.time()) + " s";
  } catch (const InstabilityError& e) {
    progress.done(solver_.time(), solver_.steps());
    status_ = e.left_domain ? kExitLeftDomain : kExitUnstable;
    message_ = e.what();
  }
  const double loop_wall = omp_get_wtime() - loop_start;  // the time loop, output included
  flush_history();
  emit_escapes();
  if (out_) {
    out_->write_end(status_, message_);
    out_->close();
  }
  const std::string ranks = opt_.stats && comm_.parallel() ? rank_stats() : std::string();
  report(loop_wall);
  if (comm_.root() && !ranks.empty()) std::fputs(ranks.c_str(), stderr);
  return status_;
}

template <class Solver>
void TimeLoop<Solver>::report(double loop_wall) const {
  if (!comm_.root()) return;  // the root speaks for every rank
  if (status_ == kExitUnstable || status_ == kExitLeftDomain) {
    std::fprintf(stderr,
                 "mpm-run: error: %s\nmpm-run: the %d frame(s) written before stay valid "
                 "(last at t = %g s)\n",
                 message_.c_str(), frame_, frame_ > 1 ? end_ * (frame_ - 1) / o_.frames : 0.0);
  } else {
    std::fprintf(stderr, "mpm-run: %s\n", message_.c_str());
  }
  extremes_.report(stderr);
  if (solver_.removed_particles() > 0)
    std::fprintf(stderr, "mpm-run: %zu particles left the domain and were removed\n",
                 solver_.removed_particles());
  if (opt_.stats) print_stats(solver_, omp_get_max_threads(), loop_wall);
}

template <class Solver>
std::string TimeLoop<Solver>::rank_stats() const {
  std::string line;
  if constexpr (!kImplicit && Solver::kRanks) {
    const auto* r = solver_.ranks();
    const double steps = double(std::max(1L, solver_.steps()));
    char b[400];
    std::snprintf(b, sizeof b,
                  "  rank %d: %zu particles, slabs along %c, %.0f shared nodes (last sort), %.0f "
                  "particles sent away; %.0f bytes and %.1f messages sent a step (%.4g MB, %.0f "
                  "messages in all)\n",
                  comm_.rank(), solver_.particles().size(), "xyz"[r ? r->axis() : 0],
                  r ? r->shared_nodes() : 0.0, r ? r->migrated() : 0.0, comm_.bytes_sent() / steps,
                  comm_.messages_sent() / steps, comm_.bytes_sent() / 1e6, comm_.messages_sent());
    line = b;
  }
  std::string out;
  std::vector<std::size_t> at;
  const std::string all = comm_.gather(line, at);
  if (comm_.root())
    out = "ranks " + std::to_string(comm_.size()) + " (domain decomposition, mpirun):\n" + all;
  return out;
}

/// --strategy patch works on the dense window of linear weights only; `why` says why not here.
void refuse_patch(ScatterStrategy strategy, const std::string& why) {
  if (strategy == ScatterStrategy::Patch)
    throw InputError("--strategy",
                     "the patch strategy " + why + " (use colored, lr-slabs or array-expansion)");
}

template <class Solver>
int run_solver(const RunOptions& opt, const Scene& scene, const Lattice& lattice, Solver& solver,
               const Restart* restart, ColumnStore* rebar = nullptr) {
  if constexpr (requires { solver.attach_rebar(*rebar); })
    if (rebar) solver.attach_rebar(*rebar);
  if (restart) solver.restore_state(restart->checkpoint.state);
  TimeLoop<Solver> loop(opt, scene, lattice, solver, restart, rebar);
  return loop();
}

/// What a refusal under mpirun adds: what the decomposition covers.
std::string under_ranks() {
  return "under mpirun (" + std::to_string(Comm::world().size()) +
         " ranks) mpm-run decomposes the explicit solver on a uniform or sparse grid with linear "
         "shape functions: run this scene without mpirun";
}

/// Under mpirun: what the domain decomposition does not cover yet, refused before the run.
void refuse_under_ranks(const Scene& scene) {
  if (!Comm::world().parallel()) return;
  auto refuse = [&](const std::string& key, const std::string& what) {
    throw InputError(key, what + " runs on one process; " + under_ranks());
  };
  if (scene.solver.type == SolverType::Implicit) refuse("solver.type", "the implicit solver");
  if (!scene.grid.levels.empty()) refuse("grid.levels", "a graded grid");
  if (scene.grid.shape != GridShape::Linear) refuse("grid.shape", "a B-spline grid");
  if (!scene.contacts.empty()) refuse("contact", "a scene with [[contact]]");
  if (!scene.rebars.empty()) refuse("rebar", "a scene with [[rebar]]");
}

template <int D>
int run(const RunOptions& opt, const Scene& scene, const Lattice& lattice, Frame& model,
        const Restart* restart, ColumnStore* rebar = nullptr) {
  refuse_under_ranks(scene);
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
    return run_solver(opt, scene, lattice, solver, restart);
  }
  const ScatterStrategy strategy = parse_strategy(opt.strategy, "--strategy");
  if (opt.deterministic && strategy != ScatterStrategy::Colored)
    throw InputError("--deterministic",
                     "only the colored strategy gives results independent of the thread count "
                     "(it is the default); drop --strategy " +
                         opt.strategy);
  if (graded) {
    refuse_patch(strategy, "needs a uniform grid; this scene has [[grid.levels]]");
    GradedGrid<D> grid(lattice, scene);
    if (restart) grid.restore_state(restart->checkpoint.state);  // before the first sort
    ExplicitSolver<GradedGrid<D>> solver(scene, std::move(grid), model.columns, strategy);
    return run_solver(opt, scene, lattice, solver, restart, rebar);
  }
  if (scene.grid.sparse) {
    refuse_patch(strategy, "cuts the dense window into slabs of nodes, and grid.sparse has none");
    ExplicitSolver<SparseGrid<D>> solver(scene, SparseGrid<D>(lattice, scene.boundary),
                                         model.columns, strategy);
    return run_solver(opt, scene, lattice, solver, restart, rebar);
  }
  if (scene.grid.shape == GridShape::Bspline) {
    refuse_patch(strategy,
                 "holds one layer of nodes past a slab's cells, and grid.shape = \"bspline\" "
                 "reaches two");
    ExplicitSolver<BsplineGrid<D>> solver(scene, BsplineGrid<D>(lattice, scene.boundary),
                                          model.columns, strategy);
    return run_solver(opt, scene, lattice, solver, restart, rebar);
  }
  UniformSolver<D> solver(scene, UniformGrid<D>(lattice, scene.boundary), model.columns, strategy);
  return run_solver(opt, scene, lattice, solver, restart, rebar);
}

/// mpm-run --restart: the run of a result stream continued from its last intact checkpoint.
int restart_model(const RunOptions& opt) {
  if (!opt.overrides.empty())
    throw InputError("--set",
                     "a restart continues the run with the scene it started with; "
                     "drop --set (or run the model again with it)");
  Restart restart;
  restart.scan = scan_for_restart(opt.restart);
  const Scene scene = parse_scene(restart.scan.scene_text, opt.restart + " (scene)", "", {});
  check_restartable(opt.restart, restart.scan);
  restart.checkpoint = load_checkpoint(opt.restart, restart.scan, &restart.rebar);
  ColumnStore* rebar = nullptr;
  if (!scene.rebars.empty()) {
    if (restart.rebar.columns.columns().empty())
      throw StreamError(opt.restart, "its checkpoint has no rebar elements (REBR) before it");
    rebar = &restart.rebar.columns;
  }
  const RestartScan& s = restart.scan;
  std::fprintf(stderr,
               "mpm-run: continuing %s from its checkpoint at step %ld, t = %g s; the %zu "
               "frame(s) before it are kept, the %llu bytes after it (%s) are recomputed\n",
               opt.restart.c_str(), long(restart.checkpoint.frame.step),
               restart.checkpoint.frame.time, s.frames_kept,
               static_cast<unsigned long long>(s.size - s.keep),
               !s.damage.empty() ? s.damage.c_str()
               : s.ended         ? ("stopped: " + s.end_message).c_str()
                                 : "cut at a record boundary");
  const Lattice lattice = make_lattice(scene);
  Frame& particles = restart.checkpoint.frame;
  if (scene.dimension == 3) return run<3>(opt, scene, lattice, particles, &restart, rebar);
  return run<2>(opt, scene, lattice, particles, &restart, rebar);
}

}  // namespace

/// Under mpirun: the root reads the model and sends every rank its scene and the particles'
/// columns (the particles themselves stay at the root until the solver's first sort hands them
/// to their ranks). A model the root cannot read fails on every rank with its message.
Model read_model_on_ranks(const RunOptions& opt) {
  const Comm& comm = Comm::world();
  Model model;
  std::string error;
  if (comm.root()) {
    try {
      model = read_model(opt);
      if (!model.rebar.columns.columns().empty())  // only the root would know
        throw InputError(
            "rebar", "a model with rebar elements (REBR) runs on one process; " + under_ranks());
    } catch (const InputError& e) {
      error = e.what();
    }
  }
  comm.broadcast(error);
  if (!error.empty()) throw InputError("", error);
  std::string scene = model.scene_text, schema = pack_schema(model.frame.columns);
  comm.broadcast(scene);
  comm.broadcast(schema);
  if (!comm.root()) {
    model.scene_text = scene;
    add_schema(model.frame.columns, schema);
  }
  return model;
}

int run_model(const RunOptions& opt) {
  if (opt.threads > 0) omp_set_num_threads(opt.threads);
  if (!opt.restart.empty() && Comm::world().parallel())
    throw InputError("--restart",
                     "continues a run on one process: run mpm-run --restart without mpirun");
  if (!opt.restart.empty()) return restart_model(opt);
  for (const auto& kv : opt.overrides)
    if (kv.rfind("bodies", 0) == 0)
      throw InputError("--set " + kv.substr(0, kv.find('=')),
                       "bodies are fixed once mpm-prep has made the particles; pass this "
                       "override to mpm-prep instead");
  Model model = Comm::world().parallel() ? read_model_on_ranks(opt) : read_model(opt);
  const std::string name = (opt.input == "-" ? std::string("stdin") : opt.input) + " (scene)";
  const Scene scene = parse_scene(model.scene_text, name, "", opt.overrides);
  const Lattice lattice = make_lattice(scene);
  const bool has_rebar = !model.rebar.columns.columns().empty();
  if (has_rebar != !scene.rebars.empty())
    throw InputError(name, has_rebar ? "the model holds rebar elements (REBR) but its scene no "
                                       "[[rebar]]"
                                     : "the scene has [[rebar]] but the model holds no rebar "
                                       "elements (REBR): make it again with this mpm-prep");
  ColumnStore* rebar = has_rebar ? &model.rebar.columns : nullptr;
  if (scene.dimension == 3) return run<3>(opt, scene, lattice, model.frame, nullptr, rebar);
  return run<2>(opt, scene, lattice, model.frame, nullptr, rebar);
}

}  // namespace mpm
