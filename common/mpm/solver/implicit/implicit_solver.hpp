#pragma once
/// Implicit MPM (001, sections 2.4 and 3.2): the theta-scheme of eq. 2.4.1,
///   m_i (v_i^L - v_i^k) = dt [theta f_i^L + (1 - theta) f_i^k + f_i^ext],
/// solved for the grid velocities (velocity formulation, symmetric: Newton-CG) or the grid
/// momenta (momentum formulation, eqs. 3.2.1-3.2.7, non-symmetric: Newton-GMRES) of the free
/// nodes, matrix-free (Jacobian products by the directional difference of eq. 2.4.18). The
/// time step is ImplicitSolver::step, at the top of implicit_solver.cpp; the residual's kernels
/// are in residual.cpp, the tangent preconditioner in tangent.cpp, the particle update after
/// convergence in commit.cpp.
///
/// Same particles, grid window, binning, materials, boundary conditions and rigid bodies as
/// the explicit solver (both are built on SolverCore, solver/core.hpp), and the same public
/// interface, so the run driver treats both alike. With theta = 0 the momentum formulation is MUSL
/// and the velocity formulation USL, step for step.
#include <algorithm>
#include <concepts>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <utility>
#include <vector>

#include "mpm/grid/grid.hpp"
#include "mpm/scene/scene.hpp"
#include "mpm/solver/core.hpp"
#include "mpm/solver/implicit/newton_krylov.hpp"

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
  /// f(name, counter) for every counter of w (const or not): what checkpoints save by name.
  template <class W, class F>
  static void each(W& w, F&& f) {
    f("steps", w.steps);
    f("newton", w.newton);
    f("krylov", w.krylov);
    f("evaluations", w.evaluations);
    f("line_search_cuts", w.line_search_cuts);
    f("step_cuts", w.step_cuts);
    f("lagrangian_cuts", w.lagrangian_cuts);
  }
};

/// A grid whose nodes have indices in the lattice of the whole domain (the warm start and
/// the tangent's unknowns survive refits of the window by them): the uniform window.
template <class G>
concept LatticeGrid = Grid<G> && requires(const G& g, std::int64_t node) {
  { g.global_node(node) } -> std::same_as<IVec<G::kDim>>;
};

struct TangentFactor;

/// Below this many particles the kernels run on one thread: a residual evaluation of a small
/// 2D scene takes microseconds, less than waking the OpenMP team (much less on a loaded
/// machine), and a Newton-Krylov step makes dozens of them.
inline constexpr std::size_t kParallelParticles = 4096;

template <LatticeGrid GridT>
class ImplicitSolver : public SolverCore<GridT> {
  using Core = SolverCore<GridT>;

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
  /// The last step taken, s.
  double last_dt() const { return last_dt_; }
  /// Work totals since the start, and of the last step (retries included).
  const ImplicitWork& work() const { return work_; }
  const ImplicitWork& last_work() const { return last_work_; }
  /// Checkpoints. settle(): the particles sorted, and the warm start and the reused tangent
  /// factor dropped, so that the step after a checkpoint starts cold both in the run that wrote
  /// it and in a run continued from it (which never had them): the two stay bitwise equal.
  void settle();
  /// The state a checkpoint holds besides the columns (SolverCore's, the step control, the
  /// work totals); restore_state() takes it back on a solver built from the saved columns.
  void save_state(StateValues& s) const;
  void restore_state(const StateValues& s);
  /// ||F||_2 of the dimensionless residual at each Newton iterate of the last attempt.
  const std::vector<double>& last_residuals() const { return last_residuals_; }

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

  // Kernels, in the order a step uses them.
  void p2g();               // m_i, P_i^k, f_i^k, f_i^ext, stiffness diagonal, rigid marks
  void free_dofs();         // Dirichlet values and the unknowns
  bool attempt(double dt);  // Newton-Krylov for one dt; true when converged and unfolded
  nk::NonlinearSystem& system_for_current(double dt, nk::Vector& u0);  // scale, guess, diagonal
  bool tangent_for(double dt);     // tangent.cpp: the last factor, or a new one
  bool factor_tangent(double dt);  // tangent.cpp: M + theta dt^2 K_t (or its momentum form)
  void to_grid(const nk::Vector& u, std::vector<Vec<D>>& w) const;  // residual.cpp ...
  void remap_trial(const std::vector<Vec<D>>& P_L, Trial& t);       // momentum: v_p^L, v_i^L
  bool stress_trial(Trial& t);  // velocity gradient, constitutive update on a copy
  void force_trial(Trial& t);   // f_i^L from the trial stress
  void residual(const nk::Vector& u, const Trial& t, nk::Vector& F) const;
  bool folds(const std::vector<Vec<D>>& v) const;  // commit.cpp: Lagrangian step restriction
  bool crosses_axis(const nk::Vector& u) const;    // axisymmetry: a particle would reach r < 0
  void reactions(const nk::Vector& u);             // forces on rigid bodies and faces
  void commit(const nk::Vector& u);                // particles: v, x, stress state; energies

  // Helpers.
  /// Runs body(chunk) on every chunk, in parallel from kParallelParticles particles.
  template <class F>
  void for_chunks(F&& body) {
    const int n = binning_.chunk_count();
    const bool parallel = particles_.size() >= kParallelParticles;
#pragma omp parallel for schedule(dynamic, 1) if (parallel)
    for (int ch = 0; ch < n; ++ch) body(ch);
  }
  /// The same for a scatter: chunks of one colour never touch the same node (binning.hpp), so
  /// they run at once, colour by colour, with no lock; each node's sum has a fixed order
  /// whatever the threads.
  template <class F>
  void for_chunks_coloured(F&& body) {
    const int n = binning_.chunk_count();
    const bool parallel = particles_.size() >= kParallelParticles;
    for (int colour = 0; colour < 2; ++colour) {
#pragma omp parallel for schedule(dynamic, 1) if (parallel)
      for (int ch = colour; ch < n; ch += 2) body(ch);
    }
  }
  /// Runs body(i, nd, nn, N, G) on each deformable particle of the bins [b0, b1): the nodes
  /// nd[0, nn) of its cell and its shape functions N and their gradients G (1/m) at x_p^k.
  template <class F>
  void for_particles(std::uint32_t b0, std::uint32_t b1, F&& body) const {
    const auto& bins = binning_.bins();
    for (std::uint32_t bi = b0; bi < b1; ++bi) {
      std::int64_t nd[NMAX];
      const int nn = grid_.cell_nodes(bins[bi].key, nd);
      for (std::uint32_t i = bins[bi].begin; i < bins[bi].end; ++i)
        if (!rigid(i)) body(i, nd, nn, &N_p_[std::size_t(i) * NMAX], &G_p_[std::size_t(i) * NMAX]);
    }
  }
  /// The same on the particles of chunk ch.
  template <class F>
  void for_particles_of_chunk(int ch, F&& body) const {
    const Chunk& chunk = binning_.chunks()[ch];
    for_particles(chunk.bin_begin, chunk.bin_end, body);
  }
  /// A scatter into a grid field: zeroes it, then runs body(i, nd, nn, N, G) (for_particles)
  /// on every deformable particle, the chunks of a colour at once.
  template <class F>
  void scatter_particles(std::vector<Vec<D>>& field, F&& body) {
    std::fill(field.begin(), field.end(), Vec<D>::Zero());
    for_chunks_coloured([&](int ch) { for_particles_of_chunk(ch, body); });
  }
  void move_velocity(const nk::Vector& u, std::vector<Vec<D>>& v_move) const;
  /// A node's velocity (or momentum) change as the particles get it: zero in the components a
  /// wall holds (the explicit solver's convention: a wall's acceleration is zero).
  Vec<D> increment(std::int64_t n, Vec<D> d) const {
    for (int a = 0; a < D; ++a)
      if (face_held_[n] >> a & 1) d[a] = 0;
    return d;
  }
  /// A node's index in the lattice (the whole domain), which survives refits of the window.
  std::int64_t global_key(std::int64_t node) const;
  void remember(const nk::Vector& u);

  using Core::axisymmetric_, Core::balance_, Core::binning_, Core::dt_, Core::exits_,
      Core::face_force_, Core::gravity_, Core::grid_, Core::has_rigid_, Core::materials_,
      Core::need_sort_, Core::node_mass_floor_, Core::particles_, Core::rigid_force_,
      Core::rigid_held_, Core::rigid_mark_, Core::marked_body_, Core::rigid_velocity_, Core::scene_,
      Core::scratch_, Core::steps_, Core::time_, Core::timers_;
  using Core::book_rigid_force, Core::reduce, Core::rigid, Core::sort_particles, Core::track_move,
      Core::update_block;

  ImplicitSpec spec_;
  double dt_explicit_ = 0, next_dt_ = 0, last_dt_ = 0;  ///< s
  double cell_measure_ = 0;  ///< dx dy (plane strain), dx dy r_ref (axisymmetric), dx dy dz
  double youngs_max_ = 0;    ///< Y of the residual scale: the largest Young's modulus

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
  nk::Vector inv_diag_;
  std::unique_ptr<TangentFactor> tangent_;  ///< the factored M + theta dt^2 K_t (tangent.hpp)
  nk::Preconditioner precond_;              ///< of the step being solved; empty: none
  bool tangent_in_use_ = false;             ///< precond_ is the tangent's factor
  nk::Vector u_;                            ///< the converged unknowns
  std::unique_ptr<Trial> trial_, accepted_;
  std::unique_ptr<System> system_;

  ImplicitWork work_, last_work_;
  std::vector<double> last_residuals_;
};

/// Trial state of one residual evaluation: the constitutive state at t^L from a trial grid
/// velocity (computed on a copy: Material::update works in place), and the grid fields.
template <LatticeGrid GridT>
struct ImplicitSolver<GridT>::Trial {
  std::vector<Sym> sigma;
  std::vector<double> rho, e, eps_p, T, thickness;
  std::vector<std::uint8_t> failed;
  std::vector<Vec<D>> v_p;  ///< momentum formulation: particle velocities v_p^L (eq. 3.2.6)
  std::vector<Vec<D>> v_i;  ///< grid velocity the strain increment came from (eq. 3.2.7)
  std::vector<Vec<D>> f_i;  ///< internal force from the trial stress (eq. 2.4.7)
  std::vector<Vec<D>> P_i;  ///< momentum formulation: trial grid momenta
  /// Sizes the state to n particles (the columns p has) and the grid fields to `nodes`.
  void resize(std::size_t n, std::size_t nodes, const ParticleView<D>& p) {
    sigma.resize(n);
    rho.resize(n);
    e.resize(n);
    eps_p.resize(p.eps_p ? n : 0);
    T.resize(p.T ? n : 0);
    thickness.resize(p.thickness ? n : 0);
    failed.resize(p.failed ? n : 0);
    v_p.resize(n);
    v_i.resize(nodes);
    f_i.resize(nodes);
    P_i.resize(nodes);
  }
  /// The particles p with this state in place of their own (the columns p has).
  ParticleView<D> view_of(const ParticleView<D>& p) {
    ParticleView<D> v = p;
    v.sigma = sigma.data();
    v.rho = rho.data();
    v.e = e.data();
    v.eps_p = p.eps_p ? eps_p.data() : nullptr;
    v.T = p.T ? T.data() : nullptr;
    v.failed = p.failed ? failed.data() : nullptr;
    v.thickness = p.thickness ? thickness.data() : nullptr;
    return v;
  }
};

}  // namespace mpm
