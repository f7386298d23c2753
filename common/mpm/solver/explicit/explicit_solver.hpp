#pragma once
/// Explicit MPM: USF, USL and MUSL with leapfrog time integration (000, section 2;
/// 004, sections 2 and 3.4), in 3D, 2D plane strain, plane stress and axisymmetry, on any grid type
/// that provides the interface described in grid.hpp (a uniform window here).
/// The time step, ExplicitSolver::step, is at the top of explicit_solver_impl.hpp.
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
#include "mpm/core/error.hpp"
#include "mpm/core/timers.hpp"
#include "mpm/grid/binning.hpp"
#include "mpm/grid/grid.hpp"
#include "mpm/grid/lattice.hpp"
#include "mpm/scene/particles.hpp"
#include "mpm/scene/scene.hpp"
#include "mpm/solver/materials/material.hpp"

namespace mpm {

/// Energies (J; per metre of thickness in plane strain, per radian in axisymmetry) and
/// momentum after a step.
struct Balance {
  double kinetic = 0;            ///< sum of m v^2 / 2 over the deformable particles
  double internal = 0;           ///< sum of m e (elastic, plastic and shock heating)
  double external_work = 0;      ///< work of body forces, loads and rigid bodies since t = 0
  double removed = 0;            ///< kinetic + internal energy of particles removed at the domain
  Vec3 momentum = Vec3::Zero();  ///< kg m/s
  /// kinetic + internal + removed - external_work. The kinetic energy is taken at the half
  /// step and the internal energy at the full step, so this swings by O(dt) in impacts.
  double total() const { return kinetic + internal + removed - external_work; }
  /// The energy central differences conserve: sum m v(k-1/2).v(k+1/2) / 2 plus the internal
  /// energy of the configuration the forces came from, at the start of the last step. No O(dt)
  /// swing: the energy guard watches this one.
  double leapfrog_total = 0;
};

/// Particles that left the domain (indices in `exits`, possibly repeated) take their energy
/// with them: it moves from kinetic and internal to `removed`. Sorts and de-duplicates
/// `exits` (the sort then drops them) and returns how many there are. Rigid particles carry
/// no energy of the balance.
template <int D>
std::size_t account_exits(ColumnStore& particles, std::vector<std::uint32_t>& exits,
                          Balance& balance) {
  if (exits.empty()) return 0;
  const ParticleView<D> p = view<D>(particles);
  std::sort(exits.begin(), exits.end());
  exits.erase(std::unique(exits.begin(), exits.end()), exits.end());
  for (auto i : exits) {
    if (p.material[i] == kRigidMaterial) continue;
    const double ke = 0.5 * p.m[i] * p.v[i].squaredNorm(), ie = p.m[i] * p.e[i];
    balance.removed += ke + ie;
    balance.kinetic -= ke;
    balance.internal -= ie;
  }
  return exits.size();
}

/// Prescribed velocities of the scene's rigid bodies, by body (zero for deformable bodies);
/// returns whether the scene has a rigid body. Shared by the explicit and implicit solvers.
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

/// Checks that every particle starts inside the grid's domain (InputError naming the first
/// that does not) and returns the nodal-mass floor below which a node counts as empty: 1e-14
/// of the lightest deformable particle.
template <class GridT>
double check_start_and_mass_floor(const GridT& grid, const ParticleView<GridT::kDim>& p) {
  double m_min = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < p.n; ++i) {
    std::int64_t key;
    Vec<GridT::kDim> xi;
    if (!p.x[i].allFinite() || grid.where(p.x[i], key, xi) == Where::OutsideDomain)
      throw InputError(
          "model", "particle " + std::to_string(p.id[i]) + " lies outside the domain of the grid");
    if (p.material[i] != kRigidMaterial) m_min = std::min(m_min, p.m[i]);
  }
  return 1e-14 * (std::isfinite(m_min) ? m_min : 1.0);
}

/// Adds the deformable particles' kinetic and internal energy and momentum to `balance` and
/// returns the fastest signal, max(reference wave speed + |v|), which sets the first step.
template <int D>
double start_balance(const ParticleView<D>& p, const std::vector<Material>& materials,
                     Balance& balance) {
  double speed = 0;
  for (std::size_t i = 0; i < p.n; ++i) {
    if (p.material[i] == kRigidMaterial) continue;
    balance.kinetic += 0.5 * p.m[i] * p.v[i].squaredNorm();
    balance.internal += p.m[i] * p.e[i];
    for (int a = 0; a < D; ++a) balance.momentum[a] += p.m[i] * p.v[i][a];
    speed = std::max(speed, materials[p.material[i]].reference_wave_speed() + p.v[i].norm());
  }
  return speed;
}

/// How the particle-to-grid scatters avoid write races without locks or atomics.
enum class ScatterStrategy {
  Colored,         ///< default: cell-ordered chunks of slab layers in two colours, balanced by
                   ///< particle count; the same bits for any thread count
  LRSlabs,         ///< 004, section 4.1: one slab set per thread, each split into L and R
                   ///< parts run alternately with a barrier between; re-balanced at every sort
  ArrayExpansion,  ///< 000, section 4.1.1: thread-private node arrays, summed after
  Patch,           ///< 000, section 4.1.2: uniform patches (slabs), one per thread, particles
                   ///< indexed per patch (Pindex/patnp) each scatter, patches assembled after
};
/// "colored", "lr-slabs", "array-expansion", "patch".
std::string to_string(ScatterStrategy s);
/// Parses a strategy name; throws InputError(where, ...) listing the names when unknown.
ScatterStrategy parse_strategy(const std::string& name, const std::string& where);

/// A run that went unstable: the step, the particle (its id) and the cause.
class InstabilityError : public std::runtime_error {
 public:
  InstabilityError(long step, double time, long particle, const std::string& cause);
  long step;
  double time;
  long particle;  ///< particle id, -1 when the cause is global (energy growth)
  std::string cause;
};

template <class GridT>
class ExplicitSolver {
 public:
  static constexpr int D = GridT::kDim;

  /// Takes the particles (columns as written by mpm-prep; state columns are added) and a grid
  /// built for the scene. The columns are reordered into cell order and stay owned by the
  /// caller.
  ExplicitSolver(const Scene& scene, GridT grid, ColumnStore& particles,
                 ScatterStrategy strategy = ScatterStrategy::Colored);
  ~ExplicitSolver();

  /// One time step of size dt (at most stable_dt()). Throws InstabilityError.
  void step(double dt);

  /// The largest stable step for the current state: cfl * h / max_p(c_p + |v_p|) (and dt_max).
  double stable_dt() const { return stable_dt_; }
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
  const GridT& grid() const { return grid_; }
  const Binning& binning() const { return binning_; }
  KernelTimers& timers() { return timers_; }
  std::size_t removed_particles() const { return removed_count_; }
  /// Particles split into 2^D children so far (graded grids, 004 section 3.3).
  long splits() const { return split_count_; }
  const Scene& scene() const { return scene_; }
  ScatterStrategy strategy() const { return strategy_; }
  /// Bytes held by the solver beyond the particle columns: grid window, private scatter
  /// arrays, sort scratch and bins.
  std::size_t work_bytes() const;

 private:
  enum Fields { kMass = 1, kMomentum = 2, kForce = 4, kRemap = 8 };
  /// Node arrays a scatter writes into; node n is element n - offset.
  struct Target {
    double* m;
    Vec<D>* v;
    Vec<D>* a;
    Vec<D>* q;
    std::int64_t offset;
  };
  /// Private node arrays of one thread (array expansion) or one patch.
  struct PrivateGrid {
    std::vector<double> m;
    std::vector<Vec<D>> v, a, q;
    std::int64_t offset = 0, size = 0;
  };
  static constexpr int NMAX = GridT::kMaxNodes;
  struct ChunkStats;
  struct StressScratch;

  // Kernels, in the order a step uses them.
  void sort_particles();
  void mark_rigid_nodes();
  template <class BinBody, class ParticleBody>
  void scatter(int fields, BinBody&& bin_body, ParticleBody&& particle_body);
  template <int F>
  void p2g();
  void grid_velocity();
  void grid_update(bool momentum_in_v);
  void grid_remap();
  void momentum_to_velocity(std::vector<Vec<D>>& field);
  template <bool Remap, bool Move>
  void g2p();
  void update_stress(const std::vector<Vec<D>>& v_grad, bool move);
  void split_particles();  // graded grids only: graded_split.hpp

  // Helpers.
  /// Cell and local coordinates of a particle of the bin of cell `bin_key`: a graded grid
  /// first tries that cell (GradedGrid::in_cell, the same result as locate without the tree
  /// search); a uniform grid's locate is as cheap as that test.
  [[gnu::always_inline]] void locate_in_bin(std::int64_t bin_key, const Vec<D>& x,
                                            std::int64_t& key, Vec<D>& xi) const {
    if constexpr (requires { grid_.in_cell(x, bin_key, xi); }) {
      if (grid_.in_cell(x, bin_key, xi)) {
        key = bin_key;
        return;
      }
    }
    grid_.locate(x, key, xi);
  }
  void apply_boundary(std::vector<Vec<D>>& vel, std::vector<Vec<D>>* acc, bool record_force);
  void track_move(const Vec<D>& x, std::uint32_t i, std::int64_t bin_key, ChunkStats& s) const;
  void finish(std::vector<ChunkStats>& stats, bool moved, bool stressed, bool velocity);
  void check_energy();
  bool rigid(std::uint32_t i) const { return material_[i] == kRigidMaterial; }

  Scene scene_;
  ColumnStore& particles_;
  GridT grid_;
  Binning binning_;
  std::vector<Material> materials_;
  Scheme scheme_;
  ScatterStrategy strategy_;
  std::vector<PrivateGrid> private_;  ///< array expansion: per thread; patch: per patch
  std::vector<std::vector<std::uint32_t>> pindex_;  ///< patch: particles of each patch
  bool axisymmetric_ = false;
  bool plane_stress_ = false;  ///< 2D: sigma_zz = 0 (the material update solves for L_zz)
  bool has_rigid_ = false;
  std::vector<Vec<D>> rigid_velocity_;    ///< by body; zero for deformable bodies
  std::vector<std::uint8_t> rigid_held_;  ///< by body: the components it imposes (bits)
  std::vector<Vec3> rigid_force_;
  Vec<D> gravity_ = Vec<D>::Zero();
  double cfl_, dt_max_;
  double dt_ = 0, time_ = 0, stable_dt_ = 0;
  long steps_ = 0;
  double particle_steps_ = 0;
  bool need_sort_ = true;
  const std::uint8_t* material_ = nullptr;  ///< refreshed with every view
  std::vector<std::uint32_t> exits_;  ///< particles that left the domain, removed at next sort
  std::size_t removed_count_ = 0;
  Balance balance_;
  double total0_ = 0, energy_scale_ = 0;
  double leapfrog_kinetic_ = 0;  ///< sum m v(k-1/2).v(k+1/2) / 2 of the last step
  std::array<double, 6> face_force_{};
  double node_mass_floor_ = 0;  ///< nodes lighter than this are treated as empty
  std::vector<std::vector<std::uint32_t>> strays_;       ///< per thread
  std::vector<std::unique_ptr<StressScratch>> scratch_;  ///< per thread
  KernelTimers timers_;
  std::uint32_t next_id_ = 0;  ///< id of the next particle a split creates (0: not yet known)
  long split_count_ = 0;       ///< particles split so far
  int split_wait_ = 0;         ///< steps the pending splits have waited for a sort
};

/// The uniform-grid solver of a scene: builds the window grid on the scene's lattice.
template <int D>
using UniformSolver = ExplicitSolver<UniformGrid<D>>;

}  // namespace mpm
