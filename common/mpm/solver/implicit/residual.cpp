// The residual's kernels of the implicit solver (001, sections 2.4 and 3.2): the unknowns to
// the grid, the momentum formulation's remap, the trial stress and internal force, and F(u).
#include <omp.h>

#include <Eigen/LU>
#include <algorithm>

#include "mpm/solver/implicit/implicit_solver.hpp"

namespace mpm {

/// Unknowns to a grid field with the prescribed values: velocities, or momenta m_i v_i.
template <LatticeGrid GridT>
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
template <LatticeGrid GridT>
void ImplicitSolver<GridT>::remap_trial(const std::vector<Vec<D>>& P_L, Trial& t) {
  ScopedTimer timer(timers_, timers_.id("remap_trial"));
  const ParticleView<D> p = view<D>(particles_);
  const double floor = node_mass_floor_;
  std::vector<Vec<D>>& q = t.v_i;
  scatter_particles(
      q, [&](std::uint32_t i, const std::int64_t* nd, int nn, const double* N, const Vec<D>*) {
        Vec<D> v = p.v[i];
        for (int c = 0; c < nn; ++c)
          if (grid_.m[nd[c]] > floor)
            v += N[c] * increment(nd[c], P_L[nd[c]] - P_k_[nd[c]]) / grid_.m[nd[c]];
        t.v_p[i] = v;
        const Vec<D> mv = p.m[i] * v;
        for (int c = 0; c < nn; ++c) q[nd[c]] += N[c] * mv;
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
template <LatticeGrid GridT>
bool ImplicitSolver<GridT>::stress_trial(Trial& t) {
  ScopedTimer timer(timers_, timers_.id("stress_trial"));
  const ParticleView<D> p = view<D>(particles_);
  const double dt = dt_;
  const bool axi = axisymmetric_;
  const double h_cell = grid_.min_cell_size();  // a lattice grid's cells are all alike
  const std::vector<Vec<D>>& v_i = t.v_i;
  std::vector<char> bad(binning_.chunk_count(), 0);

  const ParticleView<D> trial = t.view_of(p);
  for_chunks([&](int ch) {
    StressScratch& scr = *scratch_[omp_get_thread_num()];
    PendingBlock pb;
    // Constitutive update of the pending block on a copy of its state at t^k.
    auto flush = [&]() {
      if (pb.k == 0) return;
      for (std::uint32_t i = pb.i0; i < pb.i0 + std::uint32_t(pb.k); ++i)
        copy_state(p, i, trial, i);
      if (update_block(pb, trial, scr).fault_index >= 0) bad[ch] = 1;
      pb.k = 0;
    };
    for_particles_of_chunk(
        ch, [&](std::uint32_t i, const std::int64_t* nd, int nn, const double* N, const Vec<D>* G) {
          Mat3 L = Mat3::Zero();
          double v_r = 0;
          for (int c = 0; c < nn; ++c) {
            L.template topLeftCorner<D, D>().noalias() += v_i[nd[c]] * G[c].transpose();
            if (axi) v_r += N[c] * v_i[nd[c]][0];
          }
          if (axi) L(2, 2) = v_r / p.x[i][0];  // hoop rate
          if (!((Mat3::Identity() + dt * L).determinant() > 0)) bad[ch] = 1;
          if (pb.ends_before(i, p.material[i], h_cell)) {
            flush();
            pb.restart(i, p.material[i], h_cell);
          }
          scr.L[pb.k++] = L;
        });
    flush();
  });
  return std::none_of(bad.begin(), bad.end(), [](char b) { return b != 0; });
}

/// Internal force at t^L from the trial stress, at x_p^k with the volume of t^k (001,
/// eqs. 2.4.7-2.4.9: the density is kept over the step).
template <LatticeGrid GridT>
void ImplicitSolver<GridT>::force_trial(Trial& t) {
  ScopedTimer timer(timers_, timers_.id("force_trial"));
  const ParticleView<D> p = view<D>(particles_);
  const bool axi = axisymmetric_;
  scatter_particles(t.f_i, [&](std::uint32_t i, const std::int64_t* nd, int nn, const double* N,
                               const Vec<D>* G) {
    const double V_p = p.m[i] / p.rho[i];
    const Mat<D> Vsigma = V_p * to_matrix(t.sigma[i]).template topLeftCorner<D, D>();
    const double Vs_hoop_r = axi ? V_p * t.sigma[i][2] / p.x[i][0] : 0.0;
    for (int c = 0; c < nn; ++c) {
      Vec<D> fc = -Vsigma * G[c];
      if (axi) fc[0] -= Vs_hoop_r * N[c];
      t.f_i[nd[c]] += fc;
    }
  });
}

/// F(u) = M v^L - M v^k - dt [theta f^L + (1 - theta) f^k + f^ext] (001, eqs. 2.4.5, 2.4.12;
/// momentum: P^L in place of M v^L, eq. 3.2.4), on the free components, divided by the scale
/// Y dx dy dt (section 3.2.2).
template <LatticeGrid GridT>
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

template void ImplicitSolver<UniformGrid<2>>::to_grid(const nk::Vector&,
                                                      std::vector<Vec<2>>&) const;
template void ImplicitSolver<UniformGrid<3>>::to_grid(const nk::Vector&,
                                                      std::vector<Vec<3>>&) const;
template void ImplicitSolver<UniformGrid<2>>::remap_trial(const std::vector<Vec<2>>&, Trial&);
template void ImplicitSolver<UniformGrid<3>>::remap_trial(const std::vector<Vec<3>>&, Trial&);
template bool ImplicitSolver<UniformGrid<2>>::stress_trial(Trial&);
template bool ImplicitSolver<UniformGrid<3>>::stress_trial(Trial&);
template void ImplicitSolver<UniformGrid<2>>::force_trial(Trial&);
template void ImplicitSolver<UniformGrid<3>>::force_trial(Trial&);
template void ImplicitSolver<UniformGrid<2>>::residual(const nk::Vector&, const Trial&,
                                                       nk::Vector&) const;
template void ImplicitSolver<UniformGrid<3>>::residual(const nk::Vector&, const Trial&,
                                                       nk::Vector&) const;

}  // namespace mpm
