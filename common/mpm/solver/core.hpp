#pragma once
/// The solver core the explicit and implicit solvers are built on (each derives from
/// SolverCore): the particles in cell order on their grid, the materials, rigid bodies and
/// the forces on the supports, the energy balance with its guard, the particles that leave
/// the domain, the nodal-mass floor and the stable step of the initial state.
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "mpm/core/columns.hpp"
#include "mpm/core/comm.hpp"
#include "mpm/core/error.hpp"
#include "mpm/core/state_values.hpp"
#include "mpm/core/timers.hpp"
#include "mpm/grid/binning.hpp"
#include "mpm/grid/grid.hpp"
#include "mpm/scene/particles.hpp"
#include "mpm/scene/scene.hpp"
#include "mpm/solver/balance.hpp"
#include "mpm/solver/escapes.hpp"
#include "mpm/solver/materials/material.hpp"
#include "mpm/solver/ranks.hpp"

namespace mpm {

/// A run that went unstable: the step, the particle (its id) and the cause.
class InstabilityError : public std::runtime_error {
 public:
  /// left_domain: the run stopped because a particle left the domain (solver.on_exit =
  /// "stop"), which is not an instability: the message says "stopped", the exit status is 5.
  InstabilityError(long step, double time, long particle, const std::string& cause,
                   bool left_domain = false);
  long step;
  double time;
  long particle;  ///< particle id, -1 when the cause is global (energy growth)
  std::string cause;
  bool left_domain;
};

/// Prescribed velocities of the scene's rigid bodies, by body (zero for deformable bodies);
/// returns whether the scene has a rigid body.
template <int D>
bool rigid_body_velocities(const Scene& scene, std::vector<Vec<D>>& velocity) {
  velocity.assign(scene.bodies.size(), Vec<D>::Zero());
  bool any = false;
  for (std::size_t b = 0; b < scene.bodies.size(); ++b)
    if (scene.bodies[b].rigid) {
      any = true;
      for (int a = 0; a < D; ++a) velocity[b][a] = scene.bodies[b].velocity[a];
    }
  return any;
}

/// The velocity components each rigid body imposes on the nodes it touches, as bits (bit a:
/// axis a): all of them for no-slip contact, the others than its `slip` axes otherwise.
template <int D>
std::vector<std::uint8_t> rigid_body_held(const Scene& scene) {
  constexpr std::uint8_t all = (1u << D) - 1;
  std::vector<std::uint8_t> held(scene.bodies.size(), 0);
  for (std::size_t b = 0; b < scene.bodies.size(); ++b)
    if (scene.bodies[b].rigid) held[b] = std::uint8_t(all & ~scene.bodies[b].slip_axes);
  return held;
}

/// The marks rigid bodies leave on the nodes they touch (the grid's u8 column `rigid`): by
/// body, 1 + its rank among the rigid bodies (0 for deformable bodies); `marked` lists the
/// rigid bodies by mark - 1. Throws InputError past 255 rigid bodies.
inline void rigid_body_marks(const Scene& scene, std::vector<std::uint8_t>& mark,
                             std::vector<std::uint32_t>& marked) {
  mark.assign(scene.bodies.size(), 0);
  marked.clear();
  for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
    if (!scene.bodies[b].rigid) continue;
    if (marked.size() == 255)
      throw InputError(
          where(scene.source, scene.bodies[b].loc.line, "bodies." + scene.bodies[b].name),
          "a scene holds at most 255 rigid bodies");
    marked.push_back(std::uint32_t(b));
    mark[b] = std::uint8_t(marked.size());
  }
}

/// Checks that every particle starts inside the grid's domain (InputError naming the first
/// that does not) and returns the nodal-mass floor below which a node counts as empty: 1e-14
/// of the lightest deformable particle (of every rank's, with `comm`).
template <Grid GridT>
double check_start_and_mass_floor(const GridT& grid, const ParticleView<GridT::kDim>& p,
                                  const Comm* comm = nullptr) {
  double m_min = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < p.n; ++i) {
    std::int64_t key;
    Vec<GridT::kDim> xi;
    if (!p.x[i].allFinite() || grid.where(p.x[i], key, xi) == Where::OutsideDomain)
      throw InputError(
          "model", "particle " + std::to_string(p.id[i]) + " lies outside the domain of the grid");
    if (p.material[i] != kRigidMaterial) m_min = std::min(m_min, p.m[i]);
  }
  if (comm) m_min = comm->min(m_min);
  return 1e-14 * (std::isfinite(m_min) ? m_min : 1.0);
}

/// Per-thread scratch of the constitutive update.
struct StressScratch {
  Mat3 L[kBlock];                        ///< velocity gradients of the block, 1/s
  alignas(64) double L_rows[9][kBlock];  ///< or one component an array (MaterialBlock::L_rows)
  double c[kBlock];
  BlockScratch S;
};

/// A run [i0, i0 + k) of particles of one material and one cell size waiting for their
/// material update (which runs once per block, never once per particle).
struct PendingBlock {
  std::uint32_t i0 = 0;
  int k = 0;
  int mat = -1;
  double h = 0;  ///< cell size, m
  /// True when particle i of material `mat_i` in a cell of size `h_i` cannot join: another
  /// material or cell size, a full block, or a gap (a skipped rigid particle ends a block).
  bool ends_before(std::uint32_t i, int mat_i, double h_i) const {
    return mat_i != mat || k == kBlock || i != i0 + std::uint32_t(k) || h_i != h;
  }
  /// Starts the next block at particle i (after the pending one was updated).
  void restart(std::uint32_t i, int mat_i, double h_i) {
    mat = mat_i;
    i0 = i;
    h = h_i;
  }
};

/// The state and bookkeeping both solvers share; ExplicitSolver and ImplicitSolver derive
/// from it and add their step and kernels. Its accessors are the solvers' common interface.
template <Grid GridT>
class SolverCore {
 public:
  static constexpr int D = GridT::kDim;

  double time() const { return time_; }
  long steps() const { return steps_; }
  /// Particle count times steps taken, for throughput figures.
  double particle_steps() const { return particle_steps_; }
  const Balance& balance() const { return balance_; }
  /// Energy scale for the growth check: the largest of |total(0)|, kinetic and |work| so far.
  double energy_scale() const { return energy_scale_; }
  /// Force (N) carried by each constrained face in the last step, positive when the material
  /// pushes against it; faces in the order x_min, x_max, y_min, y_max, z_min, z_max.
  /// Per metre in plane strain, per radian in axisymmetry.
  const std::array<double, 6>& face_force() const { return face_force_; }
  /// Force (N) the material exerts on each rigid body in the last step (zero for the others),
  /// indexed by body.
  const std::vector<Vec3>& rigid_force() const { return rigid_force_; }
  ColumnStore& particles() { return particles_; }
  /// Particles of the run: this process's, and under mpirun every rank's (particles() holds
  /// this rank's).
  std::size_t particle_count() const {
    if constexpr (kRanks)
      if (ranks_) return ranks_->total_particles();
    return particles_.size();
  }
  /// The slab decomposition under mpirun (ranks.hpp); null in a run of one process.
  const RankSlabs<GridT>* ranks() const { return ranks_.get(); }
  static constexpr bool kRanks = requires(const GridT& g, IVec<D> k) { g.node_at(k); };
  const GridT& grid() const { return grid_; }
  const Binning& binning() const { return binning_; }
  KernelTimers& timers() { return timers_; }
  std::size_t removed_particles() const { return removed_count_; }
  /// The particles removed at the domain since the log was last cleared (by the run, once it
  /// wrote them).
  EscapeLog& escapes() { return escapes_; }
  const Scene& scene() const { return scene_; }

  /// True when the next step begins by re-sorting the particles (some left their cell's bin,
  /// the grid window or the domain).
  bool sort_pending() const { return need_sort_; }
  /// Sorts the particles into cell order now: the sort the next step would begin with when
  /// sort_pending() (the results stay bitwise the same), else an extra one (they change at
  /// round-off). After it the particle columns determine the bins and the grid window, so the
  /// columns and save_state() are the whole state: a checkpoint.
  void settle() { sort_particles(); }
  /// Writes the state between steps that the particle columns do not hold: the clock, the
  /// balance, the energy guard's reference, the counters.
  void save_state(StateValues& s) const;
  /// Restores what save_state() wrote, on a solver built from the columns saved with it.
  void restore_state(const StateValues& s);

 protected:
  /// Takes the particles (columns as written by mpm-prep; state columns are added) and a grid
  /// built for the scene; checks that they start in the domain. The columns stay the caller's.
  SolverCore(const Scene& scene, GridT grid, ColumnStore& particles);
  ~SolverCore() = default;
  /// Under mpirun, rank sums of a balance's change (the particles a sort removed).
  void reduce_removed(const Balance& d, std::size_t count);

  /// Cell order: particles that left the domain are dropped (their energy booked), the grid
  /// window refitted to the others, the columns sorted by cell.
  void sort_particles();
  /// The initial energies (the reference of the energy guard); returns the stable step of
  /// the initial state, min(dt_max, cfl h / max_p(c_p + |v_p|)).
  double start_energies();
  /// The clock after a step of dt (s), then the energy guard: InstabilityError when the
  /// energy grew beyond solver.energy_growth_limit of its scale, suggesting `remedy`.
  void end_step(double dt, const char* remedy);
  /// Where particle i (of the bin of cell `bin_key`) went when it moved to x: out of the
  /// domain, out of the window, out of its bin's cell or slab layer, or to a non-finite x.
  void track_move(const Vec<D>& x, std::uint32_t i, std::int64_t bin_key, ChunkSums& s) const;
  /// Adds each chunk's sums to `total`, in chunk order; throws on the first fault, and on a
  /// particle that left the domain unless solver.on_exit = "remove" (then it is kept in
  /// exits_ for the next sort).
  void reduce(const std::vector<ChunkSums>& chunks, ChunkSums& total);
  /// The material update of the pending block of the particles s (their own columns, or a
  /// trial copy of the state), velocity gradients in scr.L (with `rows` in scr.L_rows, one
  /// component an array); returns the block (signal speeds in scr.c, faults).
  MaterialBlock update_block(const PendingBlock& pb, const ParticleView<D>& s, StressScratch& scr,
                             bool rows = false, double* damage_increment = nullptr) const;
  /// Books the force F (N) the material exerts on rigid body `body` along `axis` in a step
  /// and the work the body does on the material.
  void book_rigid_force(int body, int axis, double F) {
    rigid_force_[body][axis] += F;
    balance_.external_work -= dt_ * F * rigid_velocity_[body][axis];
  }
  bool rigid(std::uint32_t i) const { return material_[i] == kRigidMaterial; }

  Scene scene_;
  ColumnStore& particles_;
  GridT grid_;
  Binning binning_;
  std::vector<Material> materials_;
  bool axisymmetric_ = false;
  bool plane_stress_ = false;  ///< 2D: sigma_zz = 0 (the material update solves for L_zz)
  bool has_rigid_ = false;
  std::vector<Vec<D>> rigid_velocity_;    ///< by body; zero for deformable bodies
  std::vector<std::uint8_t> rigid_held_;  ///< by body: the components it imposes (bits)
  std::vector<Vec3> rigid_force_;
  std::vector<std::uint8_t> rigid_mark_;    ///< by body: its mark on the nodes (rigid_body_marks)
  std::vector<std::uint32_t> marked_body_;  ///< by mark - 1: the rigid body
  Vec<D> gravity_ = Vec<D>::Zero();
  double dt_ = 0, time_ = 0;  ///< s: the step being taken, the time reached
  long steps_ = 0;
  double particle_steps_ = 0;
  bool need_sort_ = true;
  long sorts_ = 0;  ///< sorts so far (a sort reorders the particles: indices change)
  const std::uint8_t* material_ = nullptr;  ///< refreshed with every view
  std::vector<std::uint32_t> exits_;  ///< particles that left the domain, removed at next sort
  std::size_t removed_count_ = 0;
  EscapeLog escapes_;  ///< what they were when they left
  Balance balance_;
  double total0_ = 0, energy_scale_ = 0;
  std::array<double, 6> face_force_{};
  double node_mass_floor_ = 0;                           ///< nodes lighter count as empty
  std::vector<std::unique_ptr<StressScratch>> scratch_;  ///< per thread
  std::unique_ptr<RankSlabs<GridT>> ranks_;  ///< under mpirun (more than one rank), else null
  mutable KernelTimers timers_;              ///< const kernels (residual, fold check) are timed too
};

/// "total energy grew by ..." for the energy guard.
std::string energy_growth_message(double growth, double scale, double limit, const char* remedy);
/// "left the domain at (x, y, z) m ..." for a particle that left with on_exit = "stop".
std::string exit_message(const double* x, int dim);

template <Grid GridT>
SolverCore<GridT>::SolverCore(const Scene& scene, GridT grid, ColumnStore& particles)
    : scene_(scene),
      particles_(particles),
      grid_(std::move(grid)),
      axisymmetric_(D == 2 && scene.axisymmetric),
      plane_stress_(D == 2 && scene.plane_stress) {
  prepare_columns(particles_, scene_);
  for (const auto& m : scene_.materials) materials_.emplace_back(m, scene_.solver);
  for (int a = 0; a < D; ++a) gravity_[a] = scene_.solver.gravity[a];
  has_rigid_ = rigid_body_velocities<D>(scene_, rigid_velocity_);
  rigid_held_ = rigid_body_held<D>(scene_);
  rigid_body_marks(scene_, rigid_mark_, marked_body_);
  rigid_force_.assign(scene_.bodies.size(), Vec3::Zero());
  scratch_.resize(omp_get_max_threads());
  for (auto& s : scratch_) s = std::make_unique<StressScratch>();
  if constexpr (kRanks)
    if (Comm::world().parallel()) ranks_ = std::make_unique<RankSlabs<GridT>>(Comm::world());
  const ParticleView<D> p = view<D>(particles_);
  material_ = p.material;
  node_mass_floor_ = check_start_and_mass_floor(grid_, p, ranks_ ? &Comm::world() : nullptr);
}

template <Grid GridT>
void SolverCore<GridT>::sort_particles() {
  ScopedTimer timer(timers_, timers_.id("sort"));
  if (!ranks_) {
    removed_count_ += account_exits<D>(particles_, exits_, balance_);
    escapes_.add(particles_, exits_, time_);
    binning_.sort(particles_, grid_, exits_);
  } else if constexpr (kRanks) {
    // Under mpirun: the exits dropped and booked on every rank, the slabs cut again and the
    // particles sent to their ranks, the window fitted, the shared nodes found.
    Balance d;
    const std::size_t count = account_exits<D>(particles_, exits_, d);
    escapes_.add(particles_, exits_, time_);
    reduce_removed(d, count);
    binning_.sort(particles_, grid_, ranks_->migrate(particles_, grid_, exits_));
    ranks_->share_nodes(grid_);
  }
  exits_.clear();
  need_sort_ = false;
  ++sorts_;
  material_ = view<D>(particles_).material;
}

template <Grid GridT>
void SolverCore<GridT>::reduce_removed(const Balance& d, std::size_t count) {
  double v[11] = {d.removed,
                  d.kinetic,
                  d.internal,
                  d.removed_mass,
                  d.momentum[0],
                  d.momentum[1],
                  d.momentum[2],
                  d.removed_momentum[0],
                  d.removed_momentum[1],
                  d.removed_momentum[2],
                  double(count)};
  Comm::world().sum(v, 11);
  balance_.removed += v[0], balance_.kinetic += v[1], balance_.internal += v[2];
  balance_.removed_mass += v[3];
  for (int a = 0; a < 3; ++a)
    balance_.momentum[a] += v[4 + a], balance_.removed_momentum[a] += v[7 + a];
  removed_count_ += std::size_t(v[10]);
}

template <Grid GridT>
void SolverCore<GridT>::save_state(StateValues& s) const {
  s.set("step", double(steps_));
  s.set("time", time_);
  s.set("particle_steps", particle_steps_);
  s.set("removed_particles", double(removed_count_));
  s.set("kinetic", balance_.kinetic);
  s.set("internal", balance_.internal);
  s.set("external_work", balance_.external_work);
  s.set("removed", balance_.removed);
  for (int a = 0; a < 3; ++a) s.set(std::string("momentum_") + "xyz"[a], balance_.momentum[a]);
  s.set("leapfrog_total", balance_.leapfrog_total);
  s.set("removed_mass", balance_.removed_mass);
  for (int a = 0; a < 3; ++a)
    s.set(std::string("removed_momentum_") + "xyz"[a], balance_.removed_momentum[a]);
  s.set("total0", total0_);
  s.set("energy_scale", energy_scale_);
}

template <Grid GridT>
void SolverCore<GridT>::restore_state(const StateValues& s) {
  steps_ = long(s.get("step"));
  time_ = s.get("time");
  particle_steps_ = s.get("particle_steps");
  removed_count_ = std::size_t(s.get("removed_particles"));
  balance_.kinetic = s.get("kinetic");
  balance_.internal = s.get("internal");
  balance_.external_work = s.get("external_work");
  balance_.removed = s.get("removed");
  for (int a = 0; a < 3; ++a) balance_.momentum[a] = s.get(std::string("momentum_") + "xyz"[a]);
  balance_.leapfrog_total = s.get("leapfrog_total");
  auto optional = [&](const std::string& name) { return s.has(name) ? s.get(name) : 0.0; };
  balance_.removed_mass = optional("removed_mass");  // absent from checkpoints of stream 1.2
  for (int a = 0; a < 3; ++a)
    balance_.removed_momentum[a] = optional(std::string("removed_momentum_") + "xyz"[a]);
  total0_ = s.get("total0");
  energy_scale_ = s.get("energy_scale");
}

template <Grid GridT>
double SolverCore<GridT>::start_energies() {
  double speed = start_balance<D>(view<D>(particles_), materials_, balance_);
  if (ranks_) {  // every rank's particles, summed in rank order
    double v[5] = {balance_.kinetic, balance_.internal, balance_.momentum[0], balance_.momentum[1],
                   balance_.momentum[2]};
    Comm::world().sum(v, 5);
    balance_.kinetic = v[0], balance_.internal = v[1];
    for (int a = 0; a < 3; ++a) balance_.momentum[a] = v[2 + a];
    speed = Comm::world().max(speed);
  }
  total0_ = balance_.leapfrog_total = balance_.total();
  energy_scale_ = std::max(std::abs(total0_), balance_.kinetic);
  return stable_time_step(scene_.solver.dt_max, scene_.solver.cfl, grid_.min_cell_size(), speed);
}

template <Grid GridT>
void SolverCore<GridT>::end_step(double dt, const char* remedy) {
  time_ += dt;
  ++steps_;
  particle_steps_ += double(particle_count());
  // The energy guard.
  energy_scale_ = std::max({energy_scale_, balance_.kinetic, std::abs(balance_.external_work)});
  const double growth = balance_.leapfrog_total - total0_;
  const double limit = scene_.solver.energy_growth_limit;
  if (growth > limit * energy_scale_ && energy_scale_ > 0)
    throw InstabilityError(steps_, time_, -1,
                           energy_growth_message(growth, energy_scale_, limit, remedy));
}

template <Grid GridT>
void SolverCore<GridT>::track_move(const Vec<D>& x, std::uint32_t i, std::int64_t bin_key,
                                   ChunkSums& s) const {
  if (!x.allFinite()) {
    if (s.fault < 0) s.fault = i, s.cause = "its position is not finite";
    return;
  }
  std::int64_t key = -1;
  Vec<D> xi;
  switch (grid_.where(x, key, xi)) {
    case Where::OutsideDomain:
      s.exits.push_back(i);
      break;
    case Where::OutsideWindow:
      s.out_of_window = true;
      break;
    case Where::Window:
      if (key != bin_key) {
        ++s.off_bin;
        if (grid_.layer(key) != grid_.layer(bin_key)) ++s.strays;
      }
      break;
  }
}

template <Grid GridT>
void SolverCore<GridT>::reduce(const std::vector<ChunkSums>& chunks, ChunkSums& total) {
  const ParticleView<D> p = view<D>(particles_);
  for (const ChunkSums& s : chunks) {
    if (s.fault >= 0) throw InstabilityError(steps_ + 1, time_ + dt_, p.id[s.fault], s.cause);
    total.internal += s.internal;
    total.dt_min = std::min(total.dt_min, s.dt_min);
    total.kinetic += s.kinetic;
    total.leapfrog_kinetic += s.leapfrog_kinetic;
    total.work += s.work;
    total.work_start += s.work_start;
    total.momentum += s.momentum;
    total.off_bin += s.off_bin;
    total.strays += s.strays;
    total.out_of_window = total.out_of_window || s.out_of_window;
    for (auto i : s.exits) {
      if (scene_.solver.on_exit == OnExit::Stop)
        throw InstabilityError(steps_ + 1, time_ + dt_, p.id[i], exit_message(p.x[i].data(), D),
                               true);
      exits_.push_back(i);
    }
  }
}

template <Grid GridT>
MaterialBlock SolverCore<GridT>::update_block(const PendingBlock& pb, const ParticleView<D>& s,
                                              StressScratch& scr, bool rows,
                                              double* damage_increment) const {
  MaterialBlock blk;
  blk.n = pb.k;
  blk.dt = dt_;
  blk.h = pb.h;
  blk.h_step = grid_.min_cell_size();
  if (rows)
    blk.L_rows = scr.L_rows;
  else
    blk.L = scr.L;
  blk.m = s.m + pb.i0;
  blk.set_state(s.sigma, s.rho, s.e, s.eps_p, s.T, s.failed, s.thickness, pb.i0);
  blk.set_history(s.damage, s.mu_max, pb.i0);
  blk.damage_increment = damage_increment;
  blk.c = scr.c;
  blk.plane_stress = plane_stress_;
  materials_[pb.mat].update(blk, scr.S);
  return blk;
}

}  // namespace mpm
