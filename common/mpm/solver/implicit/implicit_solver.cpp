// Implicit MPM (001, sections 2.4 and 3.2). The time step is ImplicitSolver::step, right
// below: particle to grid, the unknowns, a Newton-Krylov solve of the theta-scheme (cut and
// retried while it fails), then the particles move. Construction, particle to grid, the
// unknowns and each attempt's set-up follow it; the residual's kernels are in residual.cpp,
// the tangent preconditioner in tangent.cpp, the particle update in commit.cpp.
#include "mpm/solver/implicit/implicit_solver.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "mpm/core/error.hpp"
#include "mpm/solver/implicit/tangent.hpp"

namespace mpm {

template <LatticeGrid GridT>
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
  ++last_work_.steps;
  work_ += last_work_;
  // The clock, the energy guard (theta >= 1/2 only dissipates).
  this->end_step(h, "raise solver.implicit.theta towards 1");
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

/// F(u) of the current step for the Newton-Krylov solver; accept() keeps the trial state.
template <LatticeGrid GridT>
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

template <LatticeGrid GridT>
ImplicitSolver<GridT>::ImplicitSolver(const Scene& scene, GridT grid, ColumnStore& particles)
    : Core(scene, std::move(grid), particles), spec_(scene.solver.implicit) {
  for (const auto& m : scene_.materials) youngs_max_ = std::max(youngs_max_, m.youngs_modulus);
  trial_ = std::make_unique<Trial>();
  accepted_ = std::make_unique<Trial>();
  system_ = std::make_unique<System>(*this);

  // Initial energies, the explicit step the multiples refer to, and the residual's cell
  // measure: dx dy in plane strain (per metre, as the seed's), dx dy r_ref in axisymmetry
  // (per radian; r_ref the mass-weighted mean radius), dx dy dz in 3D.
  dt_explicit_ = this->start_energies();
  const ParticleView<D> p = view<D>(particles_);
  double m_sum = 0, mr_sum = 0;
  for (std::size_t i = 0; i < p.n; ++i)
    if (p.material[i] != kRigidMaterial) m_sum += p.m[i], mr_sum += p.m[i] * p.x[i][0];
  if (!std::isfinite(dt_explicit_) || !(dt_explicit_ > 0))
    throw InputError(where(scene_.source, 0, "solver.dt_max"),
                     "the implicit solver needs a reference time step: the scene has no "
                     "deformable material to take it from; set solver.dt_max");
  next_dt_ = std::min(spec_.dt_initial_multiple * dt_explicit_, scene_.solver.dt_max);
  const double h = grid_.min_cell_size();
  cell_measure_ = std::pow(h, D);
  if (axisymmetric_) cell_measure_ *= m_sum > 0 ? mr_sum / m_sum : h;
}

template <LatticeGrid GridT>
ImplicitSolver<GridT>::~ImplicitSolver() = default;

template <LatticeGrid GridT>
void ImplicitSolver<GridT>::settle() {
  Core::settle();
  previous_.clear();
  tangent_.reset();
  tangent_in_use_ = false;
}

template <LatticeGrid GridT>
void ImplicitSolver<GridT>::save_state(StateValues& s) const {
  Core::save_state(s);
  s.set("implicit_dt_explicit", dt_explicit_);
  s.set("implicit_next_dt", next_dt_);
  s.set("implicit_last_dt", last_dt_);
  s.set("implicit_cell_measure", cell_measure_);
  ImplicitWork::each(work_, [&](const std::string& n, long v) { s.set("implicit_work_" + n, v); });
  ImplicitWork::each(last_work_,
                     [&](const std::string& n, long v) { s.set("implicit_last_" + n, v); });
}

template <LatticeGrid GridT>
void ImplicitSolver<GridT>::restore_state(const StateValues& s) {
  Core::restore_state(s);
  dt_explicit_ = s.get("implicit_dt_explicit");
  next_dt_ = s.get("implicit_next_dt");
  last_dt_ = s.get("implicit_last_dt");
  cell_measure_ = s.get("implicit_cell_measure");
  ImplicitWork::each(work_,
                     [&](const std::string& n, long& v) { v = long(s.get("implicit_work_" + n)); });
  ImplicitWork::each(last_work_,
                     [&](const std::string& n, long& v) { v = long(s.get("implicit_last_" + n)); });
}

template <LatticeGrid GridT>
double ImplicitSolver<GridT>::residual_scale(double dt) const {
  return youngs_max_ * cell_measure_ * dt;  // Y dx dy dt (001, section 3.2.2)
}

// ------------------------------------------------------------------------------------------
// Particle to grid at t^k: lumped mass (001, eq. 2.2.12), momentum (eq. 3.2.3), internal
// force from sigma^k (eq. 2.4.6; in axisymmetry with the hoop stress), body forces and loads,
// the diagonal of the elastic stiffness (for the preconditioner), and the nodes rigid bodies
// touch. Shape functions at x_p^k are kept: the material points' natural coordinates do not
// change in the Lagrangian step (001, section 2.4.1).

template <LatticeGrid GridT>
void ImplicitSolver<GridT>::p2g() {
  ScopedTimer timer(timers_, timers_.id("p2g"));
  grid_.clear(false, has_rigid_);
  const std::size_t nodes = grid_.nodes();
  P_k_.assign(nodes, Vec<D>::Zero());
  f_k_.assign(nodes, Vec<D>::Zero());
  f_ext_.assign(nodes, Vec<D>::Zero());
  k_diag_.assign(nodes, Vec<D>::Zero());
  const ParticleView<D> p = view<D>(particles_);
  trial_->resize(p.n, nodes, p);
  accepted_->resize(p.n, nodes, p);
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
              if (N[c] > 0) grid_.rigid[nd[c]] = rigid_mark_[p.body[i]];
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

template <LatticeGrid GridT>
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
        const std::uint32_t b = marked_body_[grid_.rigid[n] - 1];
        const std::uint8_t body = rigid_held_[b];
        held_[n] |= body;
        face_held_[n] &= std::uint8_t(~body);  // the body takes these components' force
        const Vec<D>& vb = rigid_velocity_[b];
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

template <LatticeGrid GridT>
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
    TangentFactor& T = *tangent_;
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

template <LatticeGrid GridT>
nk::NonlinearSystem& ImplicitSolver<GridT>::system_for(double dt, nk::Vector& u0) {
  sort_particles();
  p2g();
  free_dofs();
  return system_for_current(dt, u0);
}

/// The system of the step set up by p2g and free_dofs, for a step dt; u0 the initial guess.
template <LatticeGrid GridT>
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
    TangentFactor& T = *tangent_;
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

template class ImplicitSolver<UniformGrid<2>>;
template class ImplicitSolver<UniformGrid<3>>;

}  // namespace mpm
