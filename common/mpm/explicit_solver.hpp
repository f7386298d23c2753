#pragma once
/// Explicit MPM: USF, USL and MUSL with leapfrog time integration (000, section 2;
/// 004, sections 2 and 3.4). The time step is in explicit_solver.cpp, ExplicitSolver::step.
#include <array>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "mpm/binning.hpp"
#include "mpm/columns.hpp"
#include "mpm/grid.hpp"
#include "mpm/lattice.hpp"
#include "mpm/materials/material.hpp"
#include "mpm/particles.hpp"
#include "mpm/scene.hpp"
#include "mpm/timers.hpp"

namespace mpm {

/// Energies (J; per metre of thickness in 2D) and momentum after a step.
struct Balance {
  double kinetic = 0;        ///< sum of m v^2 / 2
  double internal = 0;       ///< sum of m e (elastic, plastic and shock heating)
  double external_work = 0;  ///< work done on the particles by body forces since t = 0
  double removed = 0;        ///< kinetic + internal energy of particles removed at the domain
  Vec3 momentum = Vec3::Zero();  ///< kg m/s
  /// kinetic + internal + removed - external_work. The kinetic energy is taken at the half
  /// step and the internal energy at the full step, so this swings by O(dt) in impacts.
  double total() const { return kinetic + internal + removed - external_work; }
  /// The energy central differences conserve: sum m v(k-1/2).v(k+1/2) / 2 plus the internal
  /// energy of the configuration the forces came from, at the start of the last step. No O(dt)
  /// swing: the energy guard watches this one.
  double leapfrog_total = 0;
};

/// A run that went unstable: the step, the particle (its id) and the cause.
class InstabilityError : public std::runtime_error {
 public:
  InstabilityError(long step, double time, long particle, const std::string& cause);
  long step;
  double time;
  long particle;  ///< particle id, -1 when the cause is global (energy growth)
  std::string cause;
};

template <int D>
class ExplicitSolver {
 public:
  /// Takes the particles (columns as written by mpm-prep; state columns are added). The
  /// columns are reordered into cell order and stay owned by the caller.
  ExplicitSolver(const Scene& scene, const Lattice& lattice, ColumnStore& particles);
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
  const std::array<double, 6>& face_force() const { return face_force_; }
  ColumnStore& particles() { return particles_; }
  const Grid<D>& grid() const { return grid_; }
  const Binning& binning() const { return binning_; }
  KernelTimers& timers() { return timers_; }
  std::size_t removed_particles() const { return removed_count_; }
  const Scene& scene() const { return scene_; }

 private:
  enum Fields { kMass = 1, kMomentum = 2, kForce = 4 };
  struct ChunkStats;

  // Kernels, in the order a step uses them.
  void sort_particles();
  template <int F>
  void p2g();
  void grid_velocity();
  void grid_update(bool momentum_in_v);
  void grid_remap();
  template <bool Remap, bool Move>
  void g2p();
  void update_stress(const std::vector<Vec<D>>& v_grad, bool move);

  // Helpers.
  void apply_boundary(std::vector<Vec<D>>& vel, std::vector<Vec<D>>* acc, bool record_force);
  void track_move(std::uint32_t i, std::int64_t bin_key, ChunkStats& s) const;
  void finish(std::vector<ChunkStats>& stats, bool moved, bool stressed, bool velocity);
  void check_energy();

  Scene scene_;
  ColumnStore& particles_;
  Grid<D> grid_;
  Binning binning_;
  std::vector<Material> materials_;
  Scheme scheme_;
  Vec<D> gravity_ = Vec<D>::Zero();
  double cfl_, dt_max_;
  double dt_ = 0, time_ = 0, stable_dt_ = 0;
  long steps_ = 0;
  double particle_steps_ = 0;
  bool need_sort_ = true;
  std::vector<std::uint32_t> exits_;  ///< particles that left the domain, removed at next sort
  std::size_t removed_count_ = 0;
  Balance balance_;
  double total0_ = 0, energy_scale_ = 0;
  double leapfrog_kinetic_ = 0;  ///< sum m v(k-1/2).v(k+1/2) / 2 of the last step
  std::array<double, 6> face_force_{};
  double node_mass_floor_ = 0;  ///< nodes lighter than this are treated as empty
  std::vector<std::vector<std::uint32_t>> strays_;  ///< per thread
  struct StressScratch;
  std::vector<std::unique_ptr<StressScratch>> scratch_;  ///< per thread
  KernelTimers timers_;
};

}  // namespace mpm
