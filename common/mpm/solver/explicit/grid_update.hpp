#pragma once
// Grid kernels: nodal velocities and accelerations, boundary conditions (000, eq. 6), rigid
// bodies (the nodes they touch take their velocity, in every component for no-slip contact,
// in the components other than the `slip` axes otherwise; the force that takes is the force
// between material and body).
#include "mpm/solver/explicit/explicit_solver.hpp"

namespace mpm {

template <Grid GridT>
void ExplicitSolver<GridT>::grid_velocity() {
  ScopedTimer timer(timers_, timers_.id("grid_velocity"));
  momentum_to_velocity(grid_.v);
}

template <Grid GridT>
void ExplicitSolver<GridT>::grid_update(NodeV in_v) {
  ScopedTimer timer(timers_, timers_.id("grid_update"));
  const std::int64_t n = std::int64_t(grid_.nodes());
  const double floor = node_mass_floor_, dt = dt_;
  const bool momentum_in_v = in_v == NodeV::Momentum;
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    const double m = grid_.m[i];
    if (m > floor) {
      const Vec<D> a_i = grid_.a[i] / m;
      const Vec<D> v_i = momentum_in_v ? Vec<D>(grid_.v[i] / m) : grid_.v[i];
      grid_.v[i] = v_i + dt * a_i;  // p_i^{k+1} = p_i^k + f_i dt, divided by m_i
      grid_.a[i] = a_i;
    } else if (!grid_.v[i].isZero() || !grid_.a[i].isZero()) {  // keep empty nodes at zero
      grid_.v[i].setZero();
      grid_.a[i].setZero();
    }
  }
  apply_boundary(grid_.v, &grid_.a);
}

template <Grid GridT>
void ExplicitSolver<GridT>::grid_remap() {
  ScopedTimer timer(timers_, timers_.id("grid_remap"));
  momentum_to_velocity(grid_.v_remap);
}

template <Grid GridT>
void ExplicitSolver<GridT>::momentum_to_velocity(std::vector<Vec<D>>& field) {
  const std::int64_t n = std::int64_t(grid_.nodes());
  const double floor = node_mass_floor_;
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    if (grid_.m[i] > floor)
      field[i] /= grid_.m[i];
    else if (!field[i].isZero())
      field[i].setZero();  // keep empty nodes at zero
  }
  apply_boundary(field, nullptr);
}

/// Holds the velocities (and with `acc`, grid_update's accelerations, also recording the
/// forces on the supports) where boundary conditions and rigid bodies prescribe them.
template <Grid GridT>
void ExplicitSolver<GridT>::apply_boundary(std::vector<Vec<D>>& vel, std::vector<Vec<D>>* acc) {
  const bool record_force = acc != nullptr;  // grid_update: the forces on the supports
  // Record the force each face carries (before holding the velocities), then hold them.
  if (record_force) {
    face_force_.fill(0.0);
    auto record = [&](std::int64_t n, int face) {
      const int axis = face / 2;
      const double sign = (face % 2 == 0) ? -1.0 : 1.0;
      face_force_[face] += sign * grid_.m[n] * vel[n][axis] / dt_;
    };
    for (const auto& f : grid_.fixed_nodes()) record(f.node, f.face);
    for (const auto& f : grid_.slip_nodes()) record(f.node, f.face);
  }
  for (const auto& f : grid_.fixed_nodes()) {
    vel[f.node].setZero();
    if (acc) (*acc)[f.node].setZero();
  }
  for (const auto& f : grid_.slip_nodes()) {
    vel[f.node][f.face / 2] = 0.0;
    if (acc) (*acc)[f.node][f.face / 2] = 0.0;
  }
  if (!has_rigid_) return;
  // Rigid bodies, serially (a few nodes; the force sums stay in node order).
  if (record_force)
    for (auto& f : rigid_force_) f.setZero();
  const std::int64_t n = std::int64_t(grid_.nodes());
  for (std::int64_t i = 0; i < n; ++i) {
    const int mark = grid_.rigid[i];
    if (mark == 0 || grid_.m[i] <= node_mass_floor_) continue;
    const std::uint32_t body = marked_body_[mark - 1];
    const Vec<D>& vb = rigid_velocity_[body];
    const std::uint8_t held = rigid_held_[body];  // the other components slip
    for (int a = 0; a < D; ++a) {
      if (!(held >> a & 1)) continue;
      if (record_force)  // what the body pushes back; its work on the material
        book_rigid_force(int(body), a, grid_.m[i] * (vel[i][a] - vb[a]) / dt_);
      if (acc) (*acc)[i][a] += (vb[a] - vel[i][a]) / dt_;
      vel[i][a] = vb[a];
    }
  }
}

}  // namespace mpm
