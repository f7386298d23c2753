#pragma once
/// Implicit MPM (001, sections 2.4 and 3.2): the theta-scheme of eq. 2.4.1,
///   m_i (v_i^L - v_i^k) = dt [theta f_i^L + (1 - theta) f_i^k + f_i^ext],
/// solved for the grid velocities (velocity formulation, symmetric: Newton-CG) or the grid
/// momenta (momentum formulation, eqs. 3.2.1-3.2.7, non-symmetric: Newton-GMRES) of the free
/// nodes, matrix-free (Jacobian products by the directional difference of eq. 2.4.18). The
/// time step is ImplicitSolver::step, at the top of implicit_solver.cpp.
///
/// Same particles, grid window, binning, materials, boundary conditions and rigid bodies as
/// the explicit solver (explicit_solver.hpp), and the same public interface, so the run driver
/// treats both alike. With theta = 0 the momentum formulation is MUSL and the velocity
/// formulation USL, step for step.
#include <array>
#include <memory>
#include <unordered_map>
#include <vector>

#include "mpm/core/columns.hpp"
#include "mpm/core/timers.hpp"
#include "mpm/grid/binning.hpp"
#include "mpm/grid/grid.hpp"
#include "mpm/scene/particles.hpp"
#include "mpm/scene/scene.hpp"
#include "mpm/solver/explicit/explicit_solver.hpp"  // Balance, InstabilityError
#include "mpm/solver/implicit/newton_krylov.hpp"
#include "mpm/solver/materials/material.hpp"

namespace mpm {

/// Work of the implicit solver. Failed attempts of a step (before a cut) count too.
struct ImplicitWork {
  long steps = 0;             ///< steps taken
  long newton = 0;            ///< Newton iterations (linear solves)
  long krylov = 0;            ///< Krylov iterations (Jacobian-vector products)
  long evaluations = 0;       ///< residual-operator applications, each a particle pass + scatter
  long line_search_cuts = 0;  ///< halvings of Newton steps (001, section 3.2.3)
  long step_cuts = 0;         ///< steps retried with a smaller dt
  long lagrangian_cuts = 0;   ///< of those, retried because the grid would fold
  ImplicitWork& operator+=(const ImplicitWork& o);
};

template <class GridT>
class ImplicitSolver {
 public:
  static constexpr int D = GridT::kDim;

  /// Takes the particles (columns as written by mpm-prep; state columns are added) and a grid
  /// built for the scene; the scene's solver.type must be "implicit". The columns are
  /// reordered into cell order and stay owned by the caller.
  ImplicitSolver(const Scene& scene, GridT grid, ColumnStore& particles);
  ~ImplicitSolver();

  /// One time step of dt (s), or less: the step is cut by solver.implicit.cut while Newton
  /// fails or the converged motion would fold the grid. Throws InstabilityError when
  /// solver.implicit.max_cuts cuts do not rescue it (or a particle leaves the domain).
  void step(double dt);

  /// The step the solver wants next (s): dt_initial_multiple explicit steps at first, then
  /// 1 + ramp times the last planned step, up to dt_target_multiple explicit steps (and
  /// solver.dt_max); after a cut, ramped up again from the step that succeeded.
  double stable_dt() const { return next_dt_; }
  /// The explicit (CFL) step the multiples refer to, s: cfl h / max_p(c_p + |v_p|) of the
  /// initial state (as ExplicitSolver's first step).
  double explicit_dt() const { return dt_explicit_; }
  double time() const { return time_; }
  long steps() const { return steps_; }
  /// The last step taken, s.
  double last_dt() const { return last_dt_; }
  double particle_steps() const { return particle_steps_; }
  /// Energies and momentum after the last step (leapfrog_total = total: no half steps here).
  const Balance& balance() const { return balance_; }
  /// Force (N) on each constrained face in the last step, as ExplicitSolver::face_force.
  const std::array<double, 6>& face_force() const { return face_force_; }
  /// Force (N) the material exerts on each rigid body in the last step, by body.
  const std::vector<Vec3>& rigid_force() const { return rigid_force_; }
  /// Work totals since the start, and of the last step (retries included).
  const ImplicitWork& work() const { return work_; }
  const ImplicitWork& last_work() const { return last_work_; }
  /// ||F||_2 of the dimensionless residual at each Newton iterate of the last attempt.
  const std::vector<double>& last_residuals() const { return last_residuals_; }
  ColumnStore& particles() { return particles_; }
  const GridT& grid() const { return grid_; }
  const Binning& binning() const { return binning_; }
  KernelTimers& timers() { return timers_; }
  std::size_t removed_particles() const { return removed_count_; }
  const Scene& scene() const { return scene_; }

  // For tests and studies: the nonlinear system of one step, without taking it. ----------
  /// Sets up a step of size dt from the current state (sort, particle to grid, unknowns) and
  /// returns its residual F(u) (dimensionless, 001 section 3.2.2) with the initial guess u0
  /// (v^k or P^k on the free degrees of freedom). Valid until the next call or step().
  nk::NonlinearSystem& system_for(double dt, nk::Vector& u0);
  /// The scale Y dx dy dt of the residual for a step dt (001, section 3.2.2), in the model's
  /// units of momentum (per metre in plane strain, per radian in axisymmetry).
  double residual_scale(double dt) const;
  /// Typical size of ||u|| used by the directional difference (see nk::directional_difference).
  double typical_unknown_norm() const { return u_typ_; }
  /// Inverse of the diagonal preconditioner for a step dt (empty without one).
  const nk::Vector& inverse_diagonal() const { return inv_diag_; }
  /// The Krylov solves' preconditioner for the step set up last (empty without one).
  const nk::Preconditioner& preconditioner() const { return precond_; }

 private:
  static constexpr int NMAX = GridT::kMaxNodes;
  class System;
  struct Trial;
  struct Scratch;
  struct Tangent;

  // Kernels, in the order a step uses them.
  void sort_particles();
  void p2g();               // m_i, P_i^k, f_i^k, f_i^ext, stiffness diagonal, rigid marks
  void free_dofs();         // Dirichlet values and the unknowns
  bool attempt(double dt);  // Newton-Krylov for one dt; true when converged and unfolded
  nk::NonlinearSystem& system_for_current(double dt, nk::Vector& u0);  // scale, guess, diagonal
  bool tangent_for(double dt);     // preconditioner = "tangent": the last factor, or a new one
  bool factor_tangent(double dt);  // M + theta dt^2 K_t (or its momentum form), factored
  void to_grid(const nk::Vector& u, std::vector<Vec<D>>& w) const;  // unknowns to grid
  void remap_trial(const std::vector<Vec<D>>& P_L, Trial& t);       // momentum: v_p^L, v_i^L
  bool stress_trial(Trial& t);  // velocity gradient, constitutive update on a copy
  void force_trial(Trial& t);   // f_i^L from the trial stress
  void residual(const nk::Vector& u, const Trial& t, nk::Vector& F) const;
  bool folds(const std::vector<Vec<D>>& v) const;  // Lagrangian step restriction
  bool crosses_axis(const nk::Vector& u) const;    // axisymmetry: a particle would reach r < 0
  void reactions(const nk::Vector& u);             // forces on rigid bodies and faces
  void commit(const nk::Vector& u);                // particles: v, x, stress state; energies

  // Helpers.
  template <class F>
  void for_chunks(F&& body);
  template <class F>
  void for_chunks_coloured(F&& body);
  void move_velocity(const nk::Vector& u, std::vector<Vec<D>>& v_move) const;
  bool rigid(std::uint32_t i) const { return material_[i] == kRigidMaterial; }
  /// A node's velocity (or momentum) change as the particles get it: zero in the components a
  /// wall holds (the explicit solver's convention: a wall's acceleration is zero).
  Vec<D> increment(std::int64_t n, Vec<D> d) const {
    for (int a = 0; a < D; ++a)
      if (face_held_[n] >> a & 1) d[a] = 0;
    return d;
  }

  Scene scene_;
  ImplicitSpec spec_;
  ColumnStore& particles_;
  GridT grid_;
  Binning binning_;
  std::vector<Material> materials_;
  bool axisymmetric_ = false, plane_stress_ = false, has_rigid_ = false;
  std::vector<Vec<D>> rigid_velocity_;
  std::vector<std::uint8_t> rigid_held_;  ///< by body: the components it imposes (bits)
  std::vector<Vec3> rigid_force_;
  Vec<D> gravity_ = Vec<D>::Zero();
  double dt_explicit_ = 0, next_dt_ = 0, dt_ = 0, last_dt_ = 0, time_ = 0;
  long steps_ = 0;
  double particle_steps_ = 0;
  bool need_sort_ = true;
  double cell_measure_ = 0;  ///< dx dy (plane strain), dx dy r_ref (axisymmetric), dx dy dz
  double youngs_max_ = 0;    ///< Y of the residual scale: the largest Young's modulus
  double node_mass_floor_ = 0;
  const std::uint8_t* material_ = nullptr;
  std::vector<std::uint32_t> exits_;
  std::size_t removed_count_ = 0;
  Balance balance_;
  double total0_ = 0, energy_scale_ = 0;
  std::array<double, 6> face_force_{};

  // The step being solved (grid-sized unless noted).
  std::vector<Vec<D>> P_k_;              ///< P_i^k = sum_p m_p v_p N_ip (001, eq. 3.2.3)
  std::vector<Vec<D>> v_k_;              ///< v_i^k = P_i^k / m_i (unconstrained)
  std::vector<Vec<D>> f_k_;              ///< internal force from sigma^k (001, eq. 2.4.6)
  std::vector<Vec<D>> f_ext_;            ///< body forces and loads
  std::vector<Vec<D>> k_diag_;           ///< diagonal of the elastic stiffness, N/m
  std::vector<std::uint8_t> held_;       ///< bit a: component a is prescribed (Dirichlet)
  std::vector<std::uint8_t> face_held_;  ///< bit a: ... by a wall (not a rigid body)
  std::vector<Vec<D>> v_bc_;             ///< prescribed velocities
  std::vector<std::int64_t> dof_node_;   ///< unknown -> node
  std::vector<int> dof_axis_;            ///< unknown -> component
  std::vector<double> N_p_;              ///< shape functions at x_p^k, NMAX per particle
  std::vector<Vec<D>> G_p_;              ///< their gradients, 1/m
  double u_typ_ = 0;
  /// The last accepted step's grid velocities v_i^L and masses, by global node (for
  /// initial_guess = "previous"; node indices change when the window is refitted).
  std::unordered_map<std::int64_t, std::pair<double, Vec<D>>> previous_;
  std::int64_t global_key(std::int64_t node) const;
  void remember(const nk::Vector& u);
  nk::Vector inv_diag_;
  std::unique_ptr<Tangent> tangent_;  ///< the factored M + theta dt^2 K_t (preconditioner)
  nk::Preconditioner precond_;        ///< of the step being solved; empty: none
  bool tangent_in_use_ = false;       ///< precond_ is the tangent's factor
  nk::Vector u_;                      ///< the converged unknowns
  std::unique_ptr<Trial> trial_, accepted_;
  std::unique_ptr<System> system_;
  std::vector<std::unique_ptr<Scratch>> scratch_;  ///< per thread

  ImplicitWork work_, last_work_;
  std::vector<double> last_residuals_;
  mutable KernelTimers timers_;  ///< const kernels (residual, fold check) are timed too
};

}  // namespace mpm
