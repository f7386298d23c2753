// Implicit MPM (001, sections 2.4 and 3.2). The time step is ImplicitSolver::step, right
// below: particle to grid, the unknowns, a Newton-Krylov solve of the theta-scheme (cut and
// retried while it fails), then the particles move. The residual's kernels follow it.
#include "mpm/solver/implicit/implicit_solver.hpp"

#include <omp.h>

#include <Eigen/LU>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "mpm/core/error.hpp"

namespace mpm {

template <class GridT>
void ImplicitSolver<GridT>::step(double dt) {
  if (need_sort_) sort_particles();  // cell order; the grid window follows the material
  p2g();                             // m_i, P_i^k, f_i^k, f_i^ext (001, eqs. 2.2.12, 3.2.3, 2.4.6)
  free_dofs();  // Dirichlet values; the unknowns are the rest (001, section 2.4.1)
  last_work_ = ImplicitWork{};
  double h = dt;
  for (int cut = 0; !attempt(h); ++cut) {  // F(v^L) = 0 (001, eq. 2.4.13)
    if (cut == spec_.max_cuts) {
      char msg[256];
      std::snprintf(msg, sizeof msg,
                    "the implicit step did not converge after %d cuts (last dt = %.4g s, %.3g "
                    "explicit steps; last residual %.3g): lower "
                    "solver.implicit.dt_target_multiple, or raise max_newton or max_cuts",
                    cut, h, h / dt_explicit_,
                    last_residuals_.empty() ? NAN : last_residuals_.back());
      work_ += last_work_;
      throw InstabilityError(steps_ + 1, time_ + h, -1, msg);
    }
    h *= spec_.cut;
    ++last_work_.step_cuts;
  }
  reactions(u_);  // forces on rigid bodies and constrained faces
  if (spec_.initial_guess == InitialGuess::Previous) remember(u_);
  commit(u_);  // v_p, x_p (001, eqs. 2.3.2-2.3.3 or 3.2.5-3.2.6), stress state (eq. 2.3.6)
  // Step control (001, Tables 1-6): ramp the planned step by `ramp` up to the target.
  const double base = last_work_.step_cuts > 0 ? h : std::max(h, next_dt_);
  next_dt_ = std::min(
      {base * (1.0 + spec_.ramp), spec_.dt_target_multiple * dt_explicit_, scene_.solver.dt_max});
  last_dt_ = h;
  time_ += h;
  ++steps_;
  ++last_work_.steps;
  work_ += last_work_;
  particle_steps_ += double(particles_.size());
  // Energy guard, as the explicit solver's (theta >= 1/2 only dissipates).
  energy_scale_ = std::max({energy_scale_, balance_.kinetic, std::abs(balance_.external_work)});
  const double growth = balance_.total() - total0_;
  if (energy_scale_ > 0 && growth > scene_.solver.energy_growth_limit * energy_scale_) {
    char msg[256];
    std::snprintf(msg, sizeof msg,
                  "total energy grew by %.3g J, %.1f%% of its scale %.3g J (limit "
                  "solver.energy_growth_limit = %g): raise solver.implicit.theta towards 1",
                  growth, 100.0 * growth / energy_scale_, energy_scale_,
                  scene_.solver.energy_growth_limit);
    throw InstabilityError(steps_, time_, -1, msg);
  }
}

// ------------------------------------------------------------------------------------------
// Construction and bookkeeping

ImplicitWork& ImplicitWork::operator+=(const ImplicitWork& o) {
  steps += o.steps;
  newton += o.newton;
  krylov += o.krylov;
  evaluations += o.evaluations;
  line_search_cuts += o.line_search_cuts;
  step_cuts += o.step_cuts;
  lagrangian_cuts += o.lagrangian_cuts;
  return *this;
}

/// Trial state of one residual evaluation: the constitutive state at t^L from a trial grid
/// velocity (computed on a copy: Material::update works in place), and the grid fields.
template <class GridT>
struct ImplicitSolver<GridT>::Trial {
  std::vector<Sym> sigma;
  std::vector<double> rho, e, eps_p, T, thickness;
  std::vector<std::uint8_t> failed;
  std::vector<Vec<D>> v_p;  ///< momentum formulation: particle velocities v_p^L (eq. 3.2.6)
  std::vector<Vec<D>> v_i;  ///< grid velocity the strain increment came from (eq. 3.2.7)
  std::vector<Vec<D>> f_i;  ///< internal force from the trial stress (eq. 2.4.7)
  std::vector<Vec<D>> P_i;  ///< momentum formulation: trial grid momenta
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
};

/// Per-thread scratch of the constitutive update.
template <class GridT>
struct ImplicitSolver<GridT>::Scratch {
  Mat3 L[kBlock];
  double c[kBlock];
  BlockScratch S;
};

/// F(u) of the current step for the Newton-Krylov solver; accept() keeps the trial state.
template <class GridT>
class ImplicitSolver<GridT>::System final : public nk::NonlinearSystem {
 public:
  explicit System(ImplicitSolver& s) : s_(s) {}
  bool evaluate(const nk::Vector& u, nk::Vector& F) override {
    const double t0 = omp_get_wtime();
    Trial& t = *s_.trial_;
    bool ok;
    if (s_.spec_.formulation == Formulation::Momentum) {
      s_.to_grid(u, t.P_i);      // P_i^L
      s_.remap_trial(t.P_i, t);  // v_p^L (eq. 3.2.6), v_i^L (eq. 3.2.7)
    } else {
      s_.to_grid(u, t.v_i);  // v_i^L
    }
    ok = s_.stress_trial(t);  // sigma_p^L (001, eqs. 2.2.18-2.2.21)
    if (ok) {
      s_.force_trial(t);     // f_i^L (eq. 2.4.7)
      s_.residual(u, t, F);  // (eq. 2.4.12), dimensionless
    }
    seconds += omp_get_wtime() - t0;
    return ok;
  }
  void accept() override { std::swap(s_.trial_, s_.accepted_); }
  double seconds = 0;  ///< spent in evaluate()

 private:
  ImplicitSolver& s_;
};

template <class GridT>
ImplicitSolver<GridT>::ImplicitSolver(const Scene& scene, GridT grid, ColumnStore& particles)
    : scene_(scene),
      spec_(scene.solver.implicit),
      particles_(particles),
      grid_(std::move(grid)),
      axisymmetric_(D == 2 && scene.axisymmetric),
      plane_stress_(D == 2 && scene.plane_stress) {
  prepare_columns(particles_, scene_);
  for (const auto& m : scene_.materials) {
    materials_.emplace_back(m, scene_.solver);
    youngs_max_ = std::max(youngs_max_, m.youngs_modulus);
  }
  for (int a = 0; a < D; ++a) gravity_[a] = scene_.solver.gravity[a];
  has_rigid_ = rigid_body_velocities<D>(scene_, rigid_velocity_);
  rigid_held_ = rigid_body_held<D>(scene_);
  rigid_force_.assign(scene_.bodies.size(), Vec3::Zero());
  const int threads = omp_get_max_threads();
  scratch_.resize(threads);
  for (auto& s : scratch_) s = std::make_unique<Scratch>();
  trial_ = std::make_unique<Trial>();
  accepted_ = std::make_unique<Trial>();
  system_ = std::make_unique<System>(*this);

  const ParticleView<D> p = view<D>(particles_);
  node_mass_floor_ = check_start_and_mass_floor(grid_, p);

  // Initial energies, the explicit step the multiples refer to, and the residual's cell
  // measure: dx dy in plane strain (per metre, as the seed's), dx dy r_ref in axisymmetry
  // (per radian; r_ref the mass-weighted mean radius), dx dy dz in 3D.
  const double speed = start_balance<D>(p, materials_, balance_);
  double m_sum = 0, mr_sum = 0;
  for (std::size_t i = 0; i < p.n; ++i)
    if (p.material[i] != kRigidMaterial) m_sum += p.m[i], mr_sum += p.m[i] * p.x[i][0];
  balance_.leapfrog_total = total0_ = balance_.total();
  energy_scale_ = std::max(std::abs(total0_), balance_.kinetic);
  const double h = grid_.min_cell_size();
  dt_explicit_ = std::min(scene_.solver.dt_max,
                          speed > 0 ? scene_.solver.cfl * h / speed : scene_.solver.dt_max);
  if (!std::isfinite(dt_explicit_) || !(dt_explicit_ > 0))
    throw InputError(where(scene_.source, 0, "solver.dt_max"),
                     "the implicit solver needs a reference time step: the scene has no "
                     "deformable material to take it from; set solver.dt_max");
  next_dt_ = std::min(spec_.dt_initial_multiple * dt_explicit_, scene_.solver.dt_max);
  cell_measure_ = std::pow(h, D);
  if (axisymmetric_) cell_measure_ *= m_sum > 0 ? mr_sum / m_sum : h;
}

template <class GridT>
ImplicitSolver<GridT>::~ImplicitSolver() = default;

template <class GridT>
double ImplicitSolver<GridT>::residual_scale(double dt) const {
  return youngs_max_ * cell_measure_ * dt;  // Y dx dy dt (001, section 3.2.2)
}

/// Below this many particles the kernels run on one thread: a residual evaluation of a small
/// 2D scene takes microseconds, less than waking the OpenMP team (much less on a loaded
/// machine), and a Newton-Krylov step makes dozens of them.
inline constexpr std::size_t kParallelParticles = 4096;

template <class GridT>
template <class F>
void ImplicitSolver<GridT>::for_chunks(F&& body) {
  const int n = binning_.chunk_count();
  const bool parallel = particles_.size() >= kParallelParticles;
#pragma omp parallel for schedule(dynamic, 1) if (parallel)
  for (int ch = 0; ch < n; ++ch) body(ch);
}

/// Chunks of one colour never touch the same node (binning.hpp): a scatter runs them at once,
/// colour by colour, with no lock; each node's sum has a fixed order whatever the threads.
template <class GridT>
template <class F>
void ImplicitSolver<GridT>::for_chunks_coloured(F&& body) {
  const int n = binning_.chunk_count();
  const bool parallel = particles_.size() >= kParallelParticles;
  for (int colour = 0; colour < 2; ++colour) {
#pragma omp parallel for schedule(dynamic, 1) if (parallel)
    for (int ch = colour; ch < n; ch += 2) body(ch);
  }
}

template <class GridT>
void ImplicitSolver<GridT>::sort_particles() {
  ScopedTimer timer(timers_, timers_.id("sort"));
  removed_count_ += account_exits<D>(particles_, exits_, balance_);
  binning_.sort(particles_, grid_, exits_);
  exits_.clear();
  need_sort_ = false;
  const ParticleView<D> p = view<D>(particles_);
  material_ = p.material;
  trial_->resize(p.n, grid_.nodes(), p);
  accepted_->resize(p.n, grid_.nodes(), p);
}

// ------------------------------------------------------------------------------------------
// Particle to grid at t^k: lumped mass (001, eq. 2.2.12), momentum (eq. 3.2.3), internal
// force from sigma^k (eq. 2.4.6; in axisymmetry with the hoop stress), body forces and loads,
// the diagonal of the elastic stiffness (for the preconditioner), and the nodes rigid bodies
// touch. Shape functions at x_p^k are kept: the material points' natural coordinates do not
// change in the Lagrangian step (001, section 2.4.1).

template <class GridT>
void ImplicitSolver<GridT>::p2g() {
  ScopedTimer timer(timers_, timers_.id("p2g"));
  grid_.clear(false, has_rigid_);
  const std::size_t nodes = grid_.nodes();
  P_k_.assign(nodes, Vec<D>::Zero());
  f_k_.assign(nodes, Vec<D>::Zero());
  f_ext_.assign(nodes, Vec<D>::Zero());
  k_diag_.assign(nodes, Vec<D>::Zero());
  const ParticleView<D> p = view<D>(particles_);
  N_p_.resize(p.n * NMAX);
  G_p_.resize(p.n * NMAX);
  const auto& bins = binning_.bins();
  const auto& chunks = binning_.chunks();
  const bool axi = axisymmetric_;
  const Vec<D> b = gravity_;

  for_chunks_coloured([&](int ch) {
    for (std::uint32_t bi = chunks[ch].bin_begin; bi < chunks[ch].bin_end; ++bi) {
      const Bin& bin = bins[bi];
      std::int64_t nd[NMAX];
      const int nn = grid_.cell_nodes(bin.key, nd);
      for (std::uint32_t i = bin.begin; i < bin.end; ++i) {
        std::int64_t key;
        Vec<D> xi;
        grid_.locate(p.x[i], key, xi);  // == bin.key: sorted this step
        double* N = &N_p_[i * NMAX];
        Vec<D>* G = &G_p_[i * NMAX];
        grid_.shape(key, xi, N, G);
        if (rigid(i)) {  // rigid bodies impose their velocity on the nodes they touch
          if (has_rigid_)
            for (int c = 0; c < nn; ++c)
              if (N[c] > 0) grid_.rigid[nd[c]] = std::uint8_t(p.body[i] + 1);
          continue;
        }
        const double m_p = p.m[i], V_p = m_p / p.rho[i];
        const Mat<D> Vsigma = V_p * to_matrix(p.sigma[i]).template topLeftCorner<D, D>();
        const double Vs_hoop_r = axi ? V_p * p.sigma[i][2] / p.x[i][0] : 0.0;
        const Vec<D> fb = m_p * b + (p.f_ext ? p.f_ext[i] : Vec<D>::Zero());
        const MaterialSpec& ms = scene_.materials[p.material[i]];
        const double G_mod = ms.shear_modulus(), K_mod = ms.bulk_modulus();
        const double M_mod = K_mod + 4.0 / 3.0 * G_mod, lambda = K_mod - 2.0 / 3.0 * G_mod;
        for (int c = 0; c < nn; ++c) {
          const std::int64_t n = nd[c];
          grid_.m[n] += m_p * N[c];
          P_k_[n] += N[c] * m_p * p.v[i];
          Vec<D> f = -Vsigma * G[c];          // (001, eqs. 2.2.9-2.2.10)
          if (axi) f[0] -= Vs_hoop_r * N[c];  // hoop stress (Sulsky & Schreyer 1996)
          f_k_[n] += f;
          f_ext_[n] += N[c] * fb;
          // Diagonal of the elastic stiffness: V [M G_a^2 + G sum_{b != a} G_b^2].
          const double g2 = G[c].squaredNorm();
          for (int a = 0; a < D; ++a)
            k_diag_[n][a] += V_p * (M_mod * G[c][a] * G[c][a] + G_mod * (g2 - G[c][a] * G[c][a]));
          if (axi) {
            const double Nr = N[c] / p.x[i][0];
            k_diag_[n][0] += V_p * (M_mod * Nr * Nr + 2.0 * lambda * G[c][0] * Nr);
          }
        }
      }
    }
  });
  v_k_.resize(nodes);
  for (std::size_t n = 0; n < nodes; ++n)
    v_k_[n] = grid_.m[n] > node_mass_floor_ ? Vec<D>(P_k_[n] / grid_.m[n]) : Vec<D>::Zero();
}

// ------------------------------------------------------------------------------------------
// The unknowns: every velocity (or momentum) component of every node with mass, except the
// prescribed ones (001, section 2.4.1: nodes with displacement conditions are excluded):
// fixed faces (all components), slip faces (the normal one), nodes a rigid body touches (at
// the body's velocity: all components for no-slip contact, the others than its `slip` axes
// otherwise, as in the explicit solver).

template <class GridT>
void ImplicitSolver<GridT>::free_dofs() {
  ScopedTimer timer(timers_, timers_.id("dofs"));
  const std::size_t nodes = grid_.nodes();
  constexpr std::uint8_t all = (1u << D) - 1;
  held_.assign(nodes, 0);
  v_bc_.assign(nodes, Vec<D>::Zero());
  for (const auto& f : grid_.fixed_nodes()) held_[f.node] = all;
  for (const auto& f : grid_.slip_nodes()) held_[f.node] |= std::uint8_t(1u << (f.face / 2));
  face_held_ = held_;
  if (has_rigid_)
    for (std::size_t n = 0; n < nodes; ++n)
      if (grid_.rigid[n] && grid_.m[n] > node_mass_floor_) {
        const std::uint8_t body = rigid_held_[grid_.rigid[n] - 1];
        held_[n] |= body;
        face_held_[n] &= std::uint8_t(~body);  // the body takes these components' force
        const Vec<D>& vb = rigid_velocity_[grid_.rigid[n] - 1];
        for (int a = 0; a < D; ++a)
          if (body >> a & 1) v_bc_[n][a] = vb[a];
      }
  dof_node_.clear();
  dof_axis_.clear();
  for (std::size_t n = 0; n < nodes; ++n) {
    if (!(grid_.m[n] > node_mass_floor_)) continue;
    for (int a = 0; a < D; ++a)
      if (!(held_[n] >> a & 1)) {
        dof_node_.push_back(std::int64_t(n));
        dof_axis_.push_back(a);
      }
  }
}

// ------------------------------------------------------------------------------------------
// One attempt at a step of size dt: Newton-Krylov on F = 0, then the Lagrangian step
// restriction (001, section 3.2.7: the grid's deformation gradient keeps a positive
// determinant). Returns false when either fails; the particles are not touched.

template <class GridT>
bool ImplicitSolver<GridT>::attempt(double dt) {
  nk::Vector u;
  nk::NonlinearSystem& system = system_for_current(dt, u);
  nk::Settings S;
  S.newton_tolerance = spec_.newton_tolerance;
  S.linear_tolerance = spec_.linear_tolerance;
  S.derivative_step = spec_.derivative_step;
  S.krylov = spec_.krylov;
  S.gmres_basis = spec_.gmres_basis;
  S.gmres_restarts = spec_.gmres_restarts;
  S.max_krylov = spec_.max_krylov;
  S.max_newton = spec_.max_newton;
  S.max_line_search = spec_.max_line_search;
  S.forcing = spec_.forcing;
  const double t0 = omp_get_wtime(), e0 = system_->seconds;
  const nk::Report rep = nk::solve(system, u, S, precond_ ? &precond_ : nullptr, u_typ_);
  timers_.add(timers_.id("newton_krylov"), omp_get_wtime() - t0 - (system_->seconds - e0));
  last_work_.newton += rep.work.newton;
  last_work_.krylov += rep.work.krylov;
  last_work_.evaluations += rep.work.evaluations;
  last_work_.line_search_cuts += rep.work.line_search_cuts;
  last_residuals_ = rep.residuals;
  if (tangent_in_use_) {  // how well the factor worked, for tangent_for's next decision
    Tangent& T = *tangent_;
    T.last_rate = rep.work.newton > 0 ? double(rep.work.krylov) / double(rep.work.newton) : 0.0;
    if (T.fresh_rate < 0) T.fresh_rate = T.last_rate;
    if (!rep.converged()) T.valid = false;
  }
  if (rep.outcome == nk::Outcome::InadmissibleStart) {  // the guess folds a particle's
    ++last_work_.lagrangian_cuts;                       // neighbourhood: det(I + dt L) <= 0
    return false;
  }
  if (!rep.converged()) return false;
  // The grid motion the strain came from: v_i^L (velocity formulation), or the remapped
  // v_i^L of eq. 3.2.7 (momentum formulation; P_i / m_i itself is unbounded where m_i is
  // tiny, which is why that formulation never divides by m_i alone).
  if (folds(accepted_->v_i) || crosses_axis(u)) {
    ++last_work_.lagrangian_cuts;
    return false;
  }
  u_ = std::move(u);
  return true;
}

template <class GridT>
nk::NonlinearSystem& ImplicitSolver<GridT>::system_for(double dt, nk::Vector& u0) {
  sort_particles();
  p2g();
  free_dofs();
  return system_for_current(dt, u0);
}

/// The system of the step set up by p2g and free_dofs, for a step dt; u0 the initial guess.
template <class GridT>
nk::NonlinearSystem& ImplicitSolver<GridT>::system_for_current(double dt, nk::Vector& u0) {
  dt_ = dt;
  const bool momentum = spec_.formulation == Formulation::Momentum;
  const std::size_t nd = dof_node_.size();
  const double scale = residual_scale(dt);
  // Initial guess v^k (or P^k) at the free components (001, Algorithm 1, step 1); with
  // initial_guess = "previous", the last step's v^L (m_i v^L) where the node had it with a
  // mass within a factor 2 of its mass now (a node the material has just reached, or nearly
  // left, keeps v^k: there v^L of the last step says little, and m_i v^L could be far off).
  u0.resize(Eigen::Index(nd));
  const bool warm = spec_.initial_guess == InitialGuess::Previous && !previous_.empty();
  std::int64_t warm_node = -1;
  const std::pair<double, Vec<D>>* last = nullptr;
  for (std::size_t d = 0; d < nd; ++d) {
    const std::int64_t n = dof_node_[d];
    const int a = dof_axis_[d];
    u0[d] = momentum ? P_k_[n][a] : v_k_[n][a];
    if (!warm) continue;
    if (n != warm_node) {
      warm_node = n;
      const auto it = previous_.find(global_key(n));
      const double m = grid_.m[n];
      last = it != previous_.end() && it->second.first <= 2 * m && m <= 2 * it->second.first
                 ? &it->second
                 : nullptr;
    }
    if (last) u0[d] = momentum ? grid_.m[n] * last->second[a] : last->second[a];
  }
  // Typical size of u for the directional difference: the largest speed of the particles
  // and rigid bodies on every unknown (an explicit acceleration dt f_i / m_i is no measure:
  // it is unbounded where m_i is tiny, and would make the difference step far too long).
  const ParticleView<D> p = view<D>(particles_);
  double v_ref = 0;
  for (std::size_t i = 0; i < p.n; ++i)
    if (!rigid(i)) v_ref = std::max(v_ref, p.v[i].norm());
  for (const auto& vb : rigid_velocity_) v_ref = std::max(v_ref, vb.norm());
  double typ2 = 0;
  for (std::size_t d = 0; d < nd; ++d) {
    const double t = momentum ? grid_.m[dof_node_[d]] * v_ref : v_ref;
    typ2 += t * t;
  }
  u_typ_ = std::sqrt(typ2);
  // Diagonal preconditioner: the Jacobian of the dimensionless residual is about
  // (M + theta dt^2 K) / scale (velocity) or (I + theta dt^2 K M^-1) / scale (momentum).
  // The tangent preconditioner only when the stiffness outweighs the mass (theta dt^2 sum
  // K_ii > sum m_i): below that J is close to its diagonal (at the explicit step the ratio is
  // about cfl^2; single nodes of tiny mass exceed it at any step).
  inv_diag_.resize(0);
  precond_ = nullptr;
  tangent_in_use_ = false;
  bool tangent = false;
  if (spec_.preconditioner != Preconditioner::None) {
    inv_diag_.resize(Eigen::Index(nd));
    const double th = spec_.theta;
    double stiffness = 0, mass = 0;
    for (std::size_t d = 0; d < nd; ++d) {
      const std::int64_t n = dof_node_[d];
      const double m = grid_.m[n], k = k_diag_[n][dof_axis_[d]];
      stiffness += th * dt * dt * k;
      mass += m;
      const double j = momentum ? 1.0 + th * dt * dt * k / m : m + th * dt * dt * k;
      inv_diag_[d] = scale / j;
    }
    tangent =
        spec_.preconditioner == Preconditioner::Tangent && stiffness > mass && tangent_for(dt);
    tangent_in_use_ = tangent;
    // Without it the diagonal, which helps CG and not GMRES (docs/scene.md): the momentum
    // formulation's J is then about the identity.
    if (!tangent && (spec_.preconditioner == Preconditioner::Diagonal || !momentum))
      precond_ = nk::diagonal_preconditioner(inv_diag_);
  }
  if (tangent) {
    // J ~ (M + theta dt^2 K_t) / scale (velocity) or (I + theta dt^2 K_t W) / scale
    // (momentum, W = M^-1 M_c M^-1): P^-1 r = scale times the factor's solve.
    Tangent& T = *tangent_;
    precond_ = [&T, scale, momentum](const nk::Vector& r, nk::Vector& z) {
      if (momentum)
        z = T.lu.solve(r);
      else
        z = T.ldlt.solve(r);
      z *= scale;
    };
  }
  return *system_;
}

/// The tangent preconditioner's factored matrix.
template <class GridT>
struct ImplicitSolver<GridT>::Tangent {
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;  ///< velocity: M + theta dt^2 K_t
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;          ///< momentum: I + theta dt^2 K_t W
  /// What the factor was built for: the unknowns (global node and component) and dt; and the
  /// Krylov iterations per Newton iteration of the first solve with it, and of the last.
  std::vector<std::int64_t> keys;
  double dt = 0, fresh_rate = -1, last_rate = 0;
  bool valid = false;
  /// The sparsity pattern the factor was analysed for: the ordering is reused while the
  /// pattern stays (the same unknowns, the particles in the same cells), only refactored.
  std::vector<int> outer, inner;
  template <class Solver>
  bool factor(Solver& solver, Eigen::SparseMatrix<double>& A) {
    A.makeCompressed();
    const int* o = A.outerIndexPtr();
    const int* in = A.innerIndexPtr();
    const bool same = outer.size() == std::size_t(A.outerSize() + 1) &&
                      inner.size() == std::size_t(A.nonZeros()) &&
                      std::equal(outer.begin(), outer.end(), o) &&
                      std::equal(inner.begin(), inner.end(), in);
    if (!same) {
      solver.analyzePattern(A);
      outer.assign(o, o + A.outerSize() + 1);
      inner.assign(in, in + A.nonZeros());
    }
    solver.factorize(A);
    if (solver.info() == Eigen::Success) return true;
    outer.clear();  // analyse again next time
    return false;
  }
};

/// The tangent preconditioner for a step dt: the last factor while it was built for the same
/// unknowns and dt and still works (the last solve took at most 1.5 times the Krylov
/// iterations per Newton iteration of the first solve with it, plus one), else a new one.
/// The tangent changes little from step to step at small multiples, where a factor per step
/// would cost more than the Krylov iterations it saves.
template <class GridT>
bool ImplicitSolver<GridT>::tangent_for(double dt) {
  std::vector<std::int64_t> keys(dof_node_.size());
  for (std::size_t d = 0; d < keys.size(); ++d)
    keys[d] = global_key(dof_node_[d]) * D + dof_axis_[d];
  if (tangent_ && tangent_->valid && tangent_->dt == dt && tangent_->keys == keys &&
      tangent_->last_rate <= 1.5 * tangent_->fresh_rate + 1.0)
    return true;
  if (!factor_tangent(dt)) return false;
  Tangent& T = *tangent_;
  T.keys = std::move(keys);
  T.dt = dt;
  T.valid = true;
  T.fresh_rate = -1;
  return true;
}

/// The Jacobian's estimate on the unknowns, factored: A = M + theta dt^2 K_t (velocity
/// formulation; LDL^T), or I + theta dt^2 K_t W with W = M^-1 M_c M^-1 (momentum formulation,
/// whose strain comes from the remapped velocities of eq. 3.2.7: M_c = sum_p m_p N_ip N_jp the
/// consistent mass; LU). K_t is assembled from the particles
/// at the step's start, K_t = sum_p V_p B_p^T C_p B_p (in axisymmetry B has the hoop row
/// N_i / r_p), with C_p the elastic moduli, less the plastic part for a particle on its yield
/// surface: C_ep = C - 6 G^2 / (3 G + H) n n^T, n = s / |s| and H the hardening slope of its
/// flow stress (the continuum elastic-plastic tangent of J2 flow); a failed particle keeps only
/// its bulk modulus. It is the Jacobian of the internal force of a small-strain material in
/// the state at t^k: exact for a small step of a linear elastic material, an estimate for the
/// rest (the state moves during the step; geometric terms are left out). Returns false when
/// the matrix cannot be factored (the caller falls back to the diagonal).
template <class GridT>
bool ImplicitSolver<GridT>::factor_tangent(double dt) {
  ScopedTimer timer(timers_, timers_.id("preconditioner"));
  if (!tangent_) tangent_ = std::make_unique<Tangent>();
  Tangent& T = *tangent_;
  const std::size_t nodes = grid_.nodes(), nd = dof_node_.size();
  const bool momentum = spec_.formulation == Formulation::Momentum;
  std::vector<std::int64_t> dof_of(nodes * D, -1);  // node * D + component -> unknown
  std::vector<Eigen::Triplet<double>> entries;      // M (velocity) + theta dt^2 K_t
  std::vector<Eigen::Triplet<double>> remap;        // momentum: W = M^-1 M_c M^-1 on the unknowns
  for (std::size_t d = 0; d < nd; ++d) {
    dof_of[std::size_t(dof_node_[d]) * D + std::size_t(dof_axis_[d])] = std::int64_t(d);
    if (!momentum) entries.emplace_back(int(d), int(d), grid_.m[dof_node_[d]]);
  }
  using Mat6 = Eigen::Matrix<double, 6, 6>;
  using B6 = Eigen::Matrix<double, 6, D>;  // strain (Voigt xx yy zz yz xz xy, shears doubled)
  const double c = spec_.theta * dt * dt;
  const ParticleView<D> p = view<D>(particles_);
  const bool axi = axisymmetric_;
  for (const Bin& bin : binning_.bins()) {
    std::int64_t nd_c[NMAX];
    const int nn = grid_.cell_nodes(bin.key, nd_c);
    for (std::uint32_t i = bin.begin; i < bin.end; ++i) {
      if (rigid(i)) continue;
      const Material& mat = materials_[p.material[i]];
      const bool failed = p.failed && p.failed[i];
      const double G = failed ? 0.0 : mat.shear_modulus(), K = mat.spec().bulk_modulus();
      const double lambda = K - 2.0 / 3.0 * G;
      Mat6 C = Mat6::Zero();
      C.template topLeftCorner<3, 3>().setConstant(lambda);
      for (int a = 0; a < 3; ++a) C(a, a) += 2.0 * G, C(a + 3, a + 3) = G;
      if (!failed && p.eps_p) {
        const Sym s = deviator(p.sigma[i]);
        const double s_norm = std::sqrt(ddot(s, s));
        const double Tp = p.T ? p.T[i] : 0.0, ep = p.eps_p[i];
        const double y = mat.strength().flow_stress(ep, 0.0, Tp);
        if (std::isfinite(y) && s_norm > 0 && std::sqrt(1.5) * s_norm >= (1.0 - 1e-3) * y) {
          const double de = 1e-6;
          const double H =
              std::clamp((mat.strength().flow_stress(ep + de, 0.0, Tp) - y) / de, 0.0, 1e3 * G);
          const Sym n = s / s_norm;
          C.noalias() -= 6.0 * G * G / (3.0 * G + H) * (n * n.transpose());
        }
      }
      const double V = p.m[i] / p.rho[i];
      const double* N = &N_p_[std::size_t(i) * NMAX];
      const Vec<D>* Gr = &G_p_[std::size_t(i) * NMAX];
      B6 B[NMAX];
      for (int a = 0; a < nn; ++a) {
        B[a].setZero();
        B[a](0, 0) = Gr[a][0];
        B[a](1, 1) = Gr[a][1];
        B[a](5, 0) = Gr[a][1];
        B[a](5, 1) = Gr[a][0];
        if constexpr (D == 3) {
          B[a](2, 2) = Gr[a][2];
          B[a](3, 1) = Gr[a][2];
          B[a](3, 2) = Gr[a][1];
          B[a](4, 0) = Gr[a][2];
          B[a](4, 2) = Gr[a][0];
        } else if (axi) {
          B[a](2, 0) = N[a] / p.x[i][0];
        }
      }
      if (momentum)
        for (int a = 0; a < nn; ++a)
          for (int b = 0; b < nn; ++b)
            for (int r = 0; r < D; ++r) {
              const std::int64_t row = dof_of[std::size_t(nd_c[a]) * D + std::size_t(r)];
              const std::int64_t col = dof_of[std::size_t(nd_c[b]) * D + std::size_t(r)];
              if (row >= 0 && col >= 0 && N[a] * N[b] != 0)
                remap.emplace_back(int(row), int(col),
                                   p.m[i] * N[a] * N[b] / (grid_.m[nd_c[a]] * grid_.m[nd_c[b]]));
            }
      for (int b = 0; b < nn; ++b) {
        const Eigen::Matrix<double, 6, D> CB = C * B[b];
        for (int a = 0; a < nn; ++a) {
          const Mat<D> Kab = (c * V) * (B[a].transpose() * CB);
          for (int r = 0; r < D; ++r) {
            const std::int64_t row = dof_of[std::size_t(nd_c[a]) * D + std::size_t(r)];
            if (row < 0) continue;
            for (int q = 0; q < D; ++q) {
              const std::int64_t col = dof_of[std::size_t(nd_c[b]) * D + std::size_t(q)];
              if (col >= 0 && Kab(r, q) != 0) entries.emplace_back(int(row), int(col), Kab(r, q));
            }
          }
        }
      }
    }
  }
  const auto n_unknowns = static_cast<Eigen::Index>(nd);
  Eigen::SparseMatrix<double> A(n_unknowns, n_unknowns);
  A.setFromTriplets(entries.begin(), entries.end());
  if (!momentum) return T.factor(T.ldlt, A);
  Eigen::SparseMatrix<double> W(n_unknowns, n_unknowns), I(n_unknowns, n_unknowns);
  W.setFromTriplets(remap.begin(), remap.end());
  I.setIdentity();
  Eigen::SparseMatrix<double> J = I + Eigen::SparseMatrix<double>(A * W);
  return T.factor(T.lu, J);
}

/// A node's index in the lattice (the whole domain), which survives refits of the window.
template <class GridT>
std::int64_t ImplicitSolver<GridT>::global_key(std::int64_t node) const {
  const IVec<D> g = grid_.global_node(node);
  std::int64_t k = 0;
  for (int a = D - 1; a >= 0; --a) k = (k << 21) + g[a];
  return k;
}

/// Keeps the accepted step's grid velocities (prescribed ones included) and masses for the
/// next step's initial guess.
template <class GridT>
void ImplicitSolver<GridT>::remember(const nk::Vector& u) {
  const bool momentum = spec_.formulation == Formulation::Momentum;
  std::vector<Vec<D>> w;
  to_grid(u, w);
  previous_.clear();
  const std::size_t nodes = grid_.nodes();
  for (std::size_t n = 0; n < nodes; ++n) {
    const double m = grid_.m[n];
    if (!(m > node_mass_floor_)) continue;
    previous_[global_key(std::int64_t(n))] = {m, momentum ? Vec<D>(w[n] / m) : w[n]};
  }
}

// ------------------------------------------------------------------------------------------
// The residual's kernels.

/// Unknowns to a grid field with the prescribed values: velocities, or momenta m_i v_i.
template <class GridT>
void ImplicitSolver<GridT>::to_grid(const nk::Vector& u, std::vector<Vec<D>>& w) const {
  const bool momentum = spec_.formulation == Formulation::Momentum;
  const std::size_t nodes = grid_.nodes();
  w.resize(nodes);
  for (std::size_t n = 0; n < nodes; ++n)
    w[n] = momentum ? Vec<D>(grid_.m[n] * v_bc_[n]) : v_bc_[n];  // free components overwritten
  for (std::size_t d = 0; d < dof_node_.size(); ++d) w[dof_node_[d]][dof_axis_[d]] = u[d];
}

/// Momentum formulation: particle velocities from the grid momenta (001, eq. 3.2.6,
/// v_p^L = v_p^k + sum_i N_ip (P_i^L - P_i^k) / m_i), then the Lagrangian grid velocity from
/// them by the least squares of the start of the step (eq. 3.2.7), with the prescribed values.
/// As in the explicit solver, a wall (fixed or slip face) holds the grid velocity but gives
/// the particles no increment (its acceleration is zero); a rigid body's nodes do.
template <class GridT>
void ImplicitSolver<GridT>::remap_trial(const std::vector<Vec<D>>& P_L, Trial& t) {
  ScopedTimer timer(timers_, timers_.id("remap_trial"));
  const ParticleView<D> p = view<D>(particles_);
  const auto& bins = binning_.bins();
  const auto& chunks = binning_.chunks();
  const double floor = node_mass_floor_;
  std::vector<Vec<D>>& q = t.v_i;
  std::fill(q.begin(), q.end(), Vec<D>::Zero());
  for_chunks_coloured([&](int ch) {
    for (std::uint32_t bi = chunks[ch].bin_begin; bi < chunks[ch].bin_end; ++bi) {
      std::int64_t nd[NMAX];
      const int nn = grid_.cell_nodes(bins[bi].key, nd);
      for (std::uint32_t i = bins[bi].begin; i < bins[bi].end; ++i) {
        if (rigid(i)) continue;
        const double* N = &N_p_[i * NMAX];
        Vec<D> v = p.v[i];
        for (int c = 0; c < nn; ++c)
          if (grid_.m[nd[c]] > floor)
            v += N[c] * increment(nd[c], P_L[nd[c]] - P_k_[nd[c]]) / grid_.m[nd[c]];
        t.v_p[i] = v;
        const Vec<D> mv = p.m[i] * v;
        for (int c = 0; c < nn; ++c) q[nd[c]] += N[c] * mv;
      }
    }
  });
  const std::size_t nodes = grid_.nodes();
  for (std::size_t n = 0; n < nodes; ++n) {
    q[n] = grid_.m[n] > floor ? Vec<D>(q[n] / grid_.m[n]) : Vec<D>::Zero();
    for (int a = 0; a < D; ++a)
      if (held_[n] >> a & 1) q[n][a] = v_bc_[n][a];
  }
}

/// Stress at t^L from the trial grid velocity t.v_i (001, eqs. 2.2.18-2.2.21): velocity
/// gradient at x_p^k (in axisymmetry with the hoop rate v_r / r), then the constitutive update
/// of a copy of the state of t^k, once per block of particles of one material. False when a
/// particle's motion is inadmissible: det(I + dt L_p) <= 0, or the update fails.
template <class GridT>
bool ImplicitSolver<GridT>::stress_trial(Trial& t) {
  ScopedTimer timer(timers_, timers_.id("stress_trial"));
  const ParticleView<D> p = view<D>(particles_);
  const auto& bins = binning_.bins();
  const auto& chunks = binning_.chunks();
  const double dt = dt_;
  const bool axi = axisymmetric_;
  const std::vector<Vec<D>>& v_i = t.v_i;
  std::vector<char> bad(binning_.chunk_count(), 0);

  for_chunks([&](int ch) {
    Scratch& scr = *scratch_[omp_get_thread_num()];
    std::uint32_t i0 = 0;
    int k = 0, mat = -1;
    double h_block = 0;
    // Constitutive update of the pending block [i0, i0 + k) on a copy of its state at t^k.
    auto flush = [&]() {
      if (k == 0) return;
      for (std::uint32_t i = i0; i < i0 + std::uint32_t(k); ++i) {
        t.sigma[i] = p.sigma[i];
        t.rho[i] = p.rho[i];
        t.e[i] = p.e[i];
        if (p.eps_p) t.eps_p[i] = p.eps_p[i];
        if (p.T) t.T[i] = p.T[i];
        if (p.failed) t.failed[i] = p.failed[i];
        if (p.thickness) t.thickness[i] = p.thickness[i];
      }
      MaterialBlock blk;
      blk.n = k;
      blk.dt = dt;
      blk.h = h_block;
      blk.L = scr.L;
      blk.m = p.m + i0;
      blk.sigma = t.sigma.data() + i0;
      blk.rho = t.rho.data() + i0;
      blk.e = t.e.data() + i0;
      blk.eps_p = p.eps_p ? t.eps_p.data() + i0 : nullptr;
      blk.T = p.T ? t.T.data() + i0 : nullptr;
      blk.failed = p.failed ? t.failed.data() + i0 : nullptr;
      blk.c = scr.c;
      blk.plane_stress = plane_stress_;
      blk.thickness = p.thickness ? t.thickness.data() + i0 : nullptr;
      materials_[mat].update(blk, scr.S);
      if (blk.fault_index >= 0) bad[ch] = 1;
      k = 0;
    };
    for (std::uint32_t bi = chunks[ch].bin_begin; bi < chunks[ch].bin_end; ++bi) {
      std::int64_t nd[NMAX];
      const int nn = grid_.cell_nodes(bins[bi].key, nd);
      const double h_cell = grid_.cell_size(bins[bi].key);
      for (std::uint32_t i = bins[bi].begin; i < bins[bi].end; ++i) {
        if (rigid(i)) continue;
        const double* N = &N_p_[i * NMAX];
        const Vec<D>* G = &G_p_[i * NMAX];
        Mat3 L = Mat3::Zero();
        double v_r = 0;
        for (int c = 0; c < nn; ++c) {
          L.template topLeftCorner<D, D>().noalias() += v_i[nd[c]] * G[c].transpose();
          if (axi) v_r += N[c] * v_i[nd[c]][0];
        }
        if (axi) L(2, 2) = v_r / p.x[i][0];  // hoop rate
        if (!((Mat3::Identity() + dt * L).determinant() > 0)) bad[ch] = 1;
        // A block is a contiguous run of one material: a skipped rigid particle ends it.
        if (int(p.material[i]) != mat || k == kBlock || i != i0 + std::uint32_t(k)) {
          flush();
          mat = p.material[i];
          i0 = i;
          h_block = h_cell;
        }
        scr.L[k++] = L;
      }
      if (GridT::kFixedNodes == false) flush();
    }
    flush();
  });
  return std::none_of(bad.begin(), bad.end(), [](char b) { return b != 0; });
}

/// Internal force at t^L from the trial stress, at x_p^k with the volume of t^k (001,
/// eqs. 2.4.7-2.4.9: the density is kept over the step).
template <class GridT>
void ImplicitSolver<GridT>::force_trial(Trial& t) {
  ScopedTimer timer(timers_, timers_.id("force_trial"));
  const ParticleView<D> p = view<D>(particles_);
  const auto& bins = binning_.bins();
  const auto& chunks = binning_.chunks();
  const bool axi = axisymmetric_;
  std::vector<Vec<D>>& f = t.f_i;
  std::fill(f.begin(), f.end(), Vec<D>::Zero());
  for_chunks_coloured([&](int ch) {
    for (std::uint32_t bi = chunks[ch].bin_begin; bi < chunks[ch].bin_end; ++bi) {
      std::int64_t nd[NMAX];
      const int nn = grid_.cell_nodes(bins[bi].key, nd);
      for (std::uint32_t i = bins[bi].begin; i < bins[bi].end; ++i) {
        if (rigid(i)) continue;
        const double* N = &N_p_[i * NMAX];
        const Vec<D>* G = &G_p_[i * NMAX];
        const double V_p = p.m[i] / p.rho[i];
        const Mat<D> Vsigma = V_p * to_matrix(t.sigma[i]).template topLeftCorner<D, D>();
        const double Vs_hoop_r = axi ? V_p * t.sigma[i][2] / p.x[i][0] : 0.0;
        for (int c = 0; c < nn; ++c) {
          Vec<D> fc = -Vsigma * G[c];
          if (axi) fc[0] -= Vs_hoop_r * N[c];
          f[nd[c]] += fc;
        }
      }
    }
  });
}

/// F(u) = M v^L - M v^k - dt [theta f^L + (1 - theta) f^k + f^ext] (001, eqs. 2.4.5, 2.4.12;
/// momentum: P^L in place of M v^L, eq. 3.2.4), on the free components, divided by the scale
/// Y dx dy dt (section 3.2.2).
template <class GridT>
void ImplicitSolver<GridT>::residual(const nk::Vector& u, const Trial& t, nk::Vector& F) const {
  ScopedTimer timer(timers_, timers_.id("residual"));
  const bool momentum = spec_.formulation == Formulation::Momentum;
  const double dt = dt_, th = spec_.theta, inv_scale = 1.0 / residual_scale(dt_);
  F.resize(u.size());
  for (std::size_t d = 0; d < dof_node_.size(); ++d) {
    const std::int64_t n = dof_node_[d];
    const int a = dof_axis_[d];
    const double lhs = momentum ? u[d] : grid_.m[n] * u[d];
    const double force = f_ext_[n][a] + th * t.f_i[n][a] + (1.0 - th) * f_k_[n][a];
    F[d] = (lhs - P_k_[n][a] - dt * force) * inv_scale;
  }
}

// ------------------------------------------------------------------------------------------
// After convergence: the Lagrangian step restriction, the forces on the supports, and the
// particle update.

/// The grid velocity the particles move with: v_i^L (velocity formulation, eq. 2.3.2) or
/// P_i^L / m_i (momentum formulation, eq. 3.2.5), with the prescribed values.
template <class GridT>
void ImplicitSolver<GridT>::move_velocity(const nk::Vector& u, std::vector<Vec<D>>& v_move) const {
  to_grid(u, v_move);
  if (spec_.formulation == Formulation::Momentum)
    for (std::size_t n = 0; n < v_move.size(); ++n)
      v_move[n] = grid_.m[n] > node_mass_floor_ ? Vec<D>(v_move[n] / grid_.m[n]) : Vec<D>::Zero();
}

/// True when moving the nodes by dt v folds a cell that holds material: the Jacobian of
/// the cell's mapping, at each of its corners (which bounds it for bilinear cells), must stay
/// positive (001, section 3.2.7).
template <class GridT>
bool ImplicitSolver<GridT>::folds(const std::vector<Vec<D>>& v) const {
  ScopedTimer timer(timers_, timers_.id("lagrangian_check"));
  const double h = grid_.min_cell_size(), dt = dt_;
  for (const Bin& bin : binning_.bins()) {
    bool material = false;
    for (std::uint32_t i = bin.begin; i < bin.end && !material; ++i) material = !rigid(i);
    if (!material) continue;
    std::int64_t nd[NMAX];
    const int nn = grid_.cell_nodes(bin.key, nd);
    if (nn != (1 << D)) continue;
    Vec<D> X[NMAX];  // displaced corners, relative to the lower one, in cells
    for (int c = 0; c < nn; ++c) {
      for (int a = 0; a < D; ++a) X[c][a] = (c >> a & 1) ? 1.0 : 0.0;
      X[c] += (dt / h) * v[nd[c]];
    }
    for (int c = 0; c < nn; ++c) {
      Mat<D> J;
      for (int a = 0; a < D; ++a) {
        const int lo = c & ~(1 << a), hi = c | (1 << a);
        J.col(a) = X[hi] - X[lo];
      }
      if (!(J.determinant() > 0)) return true;
    }
  }
  return false;
}

/// Axisymmetry: true when the step would carry a particle across the axis (r < 0), which no
/// motion of a solid of revolution does. The particles move with P_i^L / m_i in the momentum
/// formulation (eq. 3.2.5), not with the remapped velocity `folds` checks, and at one
/// particle per cell that motion did, after a converged step 1000 times the explicit one.
template <class GridT>
bool ImplicitSolver<GridT>::crosses_axis(const nk::Vector& u) const {
  if (!axisymmetric_) return false;
  ScopedTimer timer(timers_, timers_.id("lagrangian_check"));
  std::vector<Vec<D>> v_move;
  move_velocity(u, v_move);
  const ParticleView<D> p = view<D>(particles_);
  const double dt = dt_;
  for (const Bin& bin : binning_.bins()) {
    std::int64_t nd[NMAX];
    const int nn = grid_.cell_nodes(bin.key, nd);
    for (std::uint32_t i = bin.begin; i < bin.end; ++i) {
      if (rigid(i)) continue;
      const double* N = &N_p_[i * NMAX];
      double vr = 0;
      for (int c = 0; c < nn; ++c) vr += N[c] * v_move[nd[c]][0];
      if (p.x[i][0] + dt * vr < 0) return true;
    }
  }
  return false;
}

/// Force the material exerts on each support in the step: -R_i / dt at every prescribed
/// component, R = M v^L - M v^k - dt [theta f^L + (1 - theta) f^k + f^ext] (what the support
/// had to add). Same convention as the explicit solver: rigid bodies get the force on them,
/// faces the force pushing against them; the rigid bodies' work is booked.
template <class GridT>
void ImplicitSolver<GridT>::reactions(const nk::Vector& u) {
  ScopedTimer timer(timers_, timers_.id("reactions"));
  const bool momentum = spec_.formulation == Formulation::Momentum;
  const double dt = dt_, th = spec_.theta;
  const Trial& t = *accepted_;
  std::vector<Vec<D>> w;
  to_grid(u, w);
  auto force_on_support = [&](std::int64_t n) -> Vec<D> {
    const Vec<D> lhs = momentum ? w[n] : Vec<D>(grid_.m[n] * w[n]);
    const Vec<D> R = lhs - P_k_[n] - dt * (f_ext_[n] + th * t.f_i[n] + (1.0 - th) * f_k_[n]);
    return -R / dt;
  };
  face_force_.fill(0.0);
  auto record = [&](std::int64_t n, int face) {
    if (!(grid_.m[n] > node_mass_floor_)) return;
    const int axis = face / 2;
    if (!(face_held_[n] >> axis & 1)) return;  // a rigid body holds this component: its force
    const double sign = (face % 2 == 0) ? -1.0 : 1.0;
    face_force_[face] += sign * force_on_support(n)[axis];
  };
  for (const auto& f : grid_.fixed_nodes()) record(f.node, f.face);
  for (const auto& f : grid_.slip_nodes()) record(f.node, f.face);
  for (auto& f : rigid_force_) f.setZero();
  if (!has_rigid_) return;
  const std::int64_t nodes = std::int64_t(grid_.nodes());
  for (std::int64_t n = 0; n < nodes; ++n) {
    const int mark = grid_.rigid[n];
    if (mark == 0 || !(grid_.m[n] > node_mass_floor_)) continue;
    const Vec<D> F = force_on_support(n);
    const std::uint8_t held = rigid_held_[mark - 1];  // the other components slip
    for (int a = 0; a < D; ++a)
      if (held >> a & 1) {
        rigid_force_[mark - 1][a] += F[a];
        balance_.external_work -= dt * F[a] * rigid_velocity_[mark - 1][a];
      }
  }
}

/// Particles at t^{k+1} (001, eq. 2.3.6): velocity (eq. 2.3.3: v_p += sum N (v_i^L - v_i^k);
/// momentum formulation eq. 3.2.6, already in the accepted trial), position (eq. 2.3.2 or
/// 3.2.5), the converged constitutive state; energies and momentum.
template <class GridT>
void ImplicitSolver<GridT>::commit(const nk::Vector& u) {
  ScopedTimer timer(timers_, timers_.id("commit"));
  const bool momentum = spec_.formulation == Formulation::Momentum;
  std::vector<Vec<D>> v_move, v_L;
  move_velocity(u, v_move);
  if (!momentum) to_grid(u, v_L);
  const ParticleView<D> p = view<D>(particles_);
  const Trial& t = *accepted_;
  const auto& bins = binning_.bins();
  const auto& chunks = binning_.chunks();
  const double dt = dt_, floor = node_mass_floor_;
  const Vec<D> b = gravity_;
  struct Sums {
    double kinetic = 0, internal = 0, work = 0;
    Vec3 momentum = Vec3::Zero();
    std::vector<std::uint32_t> exits;
    long fault = -1;
    bool moved_cell = false;  ///< a particle left its bin's cell (or the window)
  };
  std::vector<Sums> sums(binning_.chunk_count());
  for_chunks([&](int ch) {
    Sums& s = sums[ch];
    for (std::uint32_t bi = chunks[ch].bin_begin; bi < chunks[ch].bin_end; ++bi) {
      std::int64_t nd[NMAX];
      const int nn = grid_.cell_nodes(bins[bi].key, nd);
      for (std::uint32_t i = bins[bi].begin; i < bins[bi].end; ++i) {
        if (rigid(i)) {
          p.x[i] += dt * p.v[i];
        } else {
          const double* N = &N_p_[i * NMAX];
          Vec<D> vbar = Vec<D>::Zero(), dv = Vec<D>::Zero();
          for (int c = 0; c < nn; ++c) {
            vbar += N[c] * v_move[nd[c]];
            if (!momentum && grid_.m[nd[c]] > floor)
              dv += N[c] * increment(nd[c], v_L[nd[c]] - v_k_[nd[c]]);
          }
          p.v[i] = momentum ? t.v_p[i] : Vec<D>(p.v[i] + dv);
          p.x[i] += dt * vbar;
          p.sigma[i] = t.sigma[i];
          p.rho[i] = t.rho[i];
          p.e[i] = t.e[i];
          if (p.eps_p) p.eps_p[i] = t.eps_p[i];
          if (p.T) p.T[i] = t.T[i];
          if (p.failed) p.failed[i] = t.failed[i];
          if (p.thickness) p.thickness[i] = t.thickness[i];
          s.kinetic += 0.5 * p.m[i] * p.v[i].squaredNorm();
          s.internal += p.m[i] * p.e[i];
          for (int a = 0; a < D; ++a) s.momentum[a] += p.m[i] * p.v[i][a];
          s.work += dt * (p.m[i] * b + (p.f_ext ? p.f_ext[i] : Vec<D>::Zero())).dot(p.v[i]);
        }
        std::int64_t key = -1;
        Vec<D> xi;
        if (!p.x[i].allFinite()) {
          if (s.fault < 0) s.fault = i;
        } else {
          const Where w = grid_.where(p.x[i], key, xi);
          if (w == Where::OutsideDomain) s.exits.push_back(i);
          if (w != Where::Window || key != bins[bi].key) s.moved_cell = true;
        }
      }
    }
  });
  balance_.kinetic = balance_.internal = 0;
  balance_.momentum.setZero();
  for (const Sums& s : sums) {
    if (s.fault >= 0)
      throw InstabilityError(steps_ + 1, time_ + dt, p.id[s.fault], "its position is not finite");
    balance_.kinetic += s.kinetic;
    balance_.internal += s.internal;
    balance_.momentum += s.momentum;
    balance_.external_work += s.work;
    if (s.moved_cell) need_sort_ = true;  // the kernels take every particle in its bin's cell
    for (auto i : s.exits) {
      if (scene_.solver.on_exit == OnExit::Stop) {
        char where_[160];
        std::snprintf(where_, sizeof where_, "left the domain at (%.4g, %.4g, %.4g) m", p.x[i][0],
                      p.x[i][1], D == 3 ? p.x[i][D - 1] : 0.0);
        throw InstabilityError(
            steps_ + 1, time_ + dt, p.id[i],
            std::string(where_) + " (enlarge grid.domain, or set solver.on_exit = \"remove\")");
      }
      exits_.push_back(i);
    }
  }
  balance_.leapfrog_total = balance_.total();
}

template class ImplicitSolver<UniformGrid<2>>;
template class ImplicitSolver<UniformGrid<3>>;

}  // namespace mpm
