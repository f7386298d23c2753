// After an implicit step converged (001, sections 2.3 and 3.2.7): the Lagrangian step
// restriction, the forces on the supports, the particle update, and the grid velocities kept
// for the next step's initial guess.
#include <Eigen/LU>
#include <cmath>

#include "mpm/solver/implicit/implicit_solver.hpp"

namespace mpm {

/// The grid velocity the particles move with: v_i^L (velocity formulation, eq. 2.3.2) or
/// P_i^L / m_i (momentum formulation, eq. 3.2.5), with the prescribed values.
template <LatticeGrid GridT>
void ImplicitSolver<GridT>::move_velocity(const nk::Vector& u, std::vector<Vec<D>>& v_move) const {
  to_grid(u, v_move);
  if (spec_.formulation == Formulation::Momentum)
    for (std::size_t n = 0; n < v_move.size(); ++n)
      v_move[n] = grid_.m[n] > node_mass_floor_ ? Vec<D>(v_move[n] / grid_.m[n]) : Vec<D>::Zero();
}

/// True when moving the nodes by dt v folds a cell that holds material: the Jacobian of
/// the cell's mapping, at each of its corners (which bounds it for bilinear cells), must stay
/// positive (001, section 3.2.7).
template <LatticeGrid GridT>
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
template <LatticeGrid GridT>
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
template <LatticeGrid GridT>
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
    const std::uint32_t body = marked_body_[mark - 1];
    const std::uint8_t held = rigid_held_[body];  // the other components slip
    for (int a = 0; a < D; ++a)
      if (held >> a & 1) book_rigid_force(int(body), a, F[a]);
  }
}

/// Particles at t^{k+1} (001, eq. 2.3.6): velocity (eq. 2.3.3: v_p += sum N (v_i^L - v_i^k);
/// momentum formulation eq. 3.2.6, already in the accepted trial), position (eq. 2.3.2 or
/// 3.2.5), the converged constitutive state; energies and momentum.
template <LatticeGrid GridT>
void ImplicitSolver<GridT>::commit(const nk::Vector& u) {
  ScopedTimer timer(timers_, timers_.id("commit"));
  const bool momentum = spec_.formulation == Formulation::Momentum;
  std::vector<Vec<D>> v_move, v_L;
  move_velocity(u, v_move);
  if (!momentum) to_grid(u, v_L);
  const ParticleView<D> p = view<D>(particles_);
  Trial& t = *accepted_;
  const auto& bins = binning_.bins();
  const auto& chunks = binning_.chunks();
  const double dt = dt_, floor = node_mass_floor_;
  const ParticleView<D> trial = t.view_of(p);
  std::vector<ChunkSums> sums(binning_.chunk_count());
  for_chunks([&](int ch) {
    ChunkSums& s = sums[ch];
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
          const Vec<D> v_old = p.v[i];
          p.v[i] = momentum ? t.v_p[i] : Vec<D>(p.v[i] + dv);
          p.x[i] += dt * vbar;
          copy_state(trial, i, p, i);
          s.internal += p.m[i] * p.e[i];
          s.add_motion(p, i);
          s.add_load_work(p, i, dt, gravity_, v_old);
        }
        track_move(p.x[i], i, bins[bi].key, s);
      }
    }
  });
  ChunkSums total;
  total.work = balance_.external_work;  // the chunks' work is added to it in chunk order
  reduce(sums, total);
  balance_.kinetic = total.kinetic;
  balance_.internal = total.internal;
  balance_.momentum = total.momentum;
  balance_.external_work = total.work;
  // The kernels take every particle in its bin's cell.
  if (total.off_bin > 0 || total.out_of_window || !exits_.empty()) need_sort_ = true;
  balance_.leapfrog_total = balance_.total();
}

template <LatticeGrid GridT>
std::int64_t ImplicitSolver<GridT>::global_key(std::int64_t node) const {
  const IVec<D> g = grid_.global_node(node);
  std::int64_t k = 0;
  for (int a = D - 1; a >= 0; --a) k = (k << 21) + g[a];
  return k;
}

/// Keeps the accepted step's grid velocities (prescribed ones included) and masses for the
/// next step's initial guess.
template <LatticeGrid GridT>
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

template bool ImplicitSolver<UniformGrid<2>>::folds(const std::vector<Vec<2>>&) const;
template bool ImplicitSolver<UniformGrid<3>>::folds(const std::vector<Vec<3>>&) const;
template bool ImplicitSolver<UniformGrid<2>>::crosses_axis(const nk::Vector&) const;
template bool ImplicitSolver<UniformGrid<3>>::crosses_axis(const nk::Vector&) const;
template void ImplicitSolver<UniformGrid<2>>::reactions(const nk::Vector&);
template void ImplicitSolver<UniformGrid<3>>::reactions(const nk::Vector&);
template void ImplicitSolver<UniformGrid<2>>::commit(const nk::Vector&);
template void ImplicitSolver<UniformGrid<3>>::commit(const nk::Vector&);
template std::int64_t ImplicitSolver<UniformGrid<2>>::global_key(std::int64_t) const;
template std::int64_t ImplicitSolver<UniformGrid<3>>::global_key(std::int64_t) const;
template void ImplicitSolver<UniformGrid<2>>::remember(const nk::Vector&);
template void ImplicitSolver<UniformGrid<3>>::remember(const nk::Vector&);

}  // namespace mpm
