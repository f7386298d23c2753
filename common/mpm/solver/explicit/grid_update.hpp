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
  momentum_to_velocity(grid_.m.data(), grid_.v.data());
  for (int f = 1; f < contact_.field_count(); ++f)
    momentum_to_velocity(contact_.field(f).m.data(), contact_.field(f).v.data());
  exchange_momentum(Exchange::Velocity);
  apply_boundary(Exchange::Velocity);
}

template <Grid GridT>
void ExplicitSolver<GridT>::grid_update(NodeV in_v) {
  ScopedTimer timer(timers_, timers_.id("grid_update"));
  const double work_before = balance_.external_work;
  integrate_nodes(grid_.m.data(), grid_.v.data(), grid_.a.data(), in_v);
  for (int f = 1; f < contact_.field_count(); ++f) {
    auto& fd = contact_.field(f);
    integrate_nodes(fd.m.data(), fd.v.data(), fd.a.data(), in_v);
  }
  exchange_momentum(Exchange::Update);
  apply_boundary(Exchange::Update);
  if (ranks_) reduce_support_forces(work_before);
}

/// Under mpirun: the forces on the faces and rigid bodies (each node counted by its owner) and
/// the rigid bodies' work in the step, added over the ranks in rank order.
template <Grid GridT>
void ExplicitSolver<GridT>::reduce_support_forces(double work_before) {
  std::vector<double> v(face_force_.begin(), face_force_.end());
  v.push_back(balance_.external_work - work_before);
  if (has_rigid_)
    for (const Vec3& f : rigid_force_) v.insert(v.end(), {f[0], f[1], f[2]});
  Comm::world().sum(v.data(), int(v.size()));
  std::copy(v.begin(), v.begin() + 6, face_force_.begin());
  balance_.external_work = work_before + v[6];
  if (has_rigid_)
    for (std::size_t b = 0; b < rigid_force_.size(); ++b)
      for (int a = 0; a < 3; ++a) rigid_force_[b][a] = v[7 + 3 * b + std::size_t(a)];
}

template <Grid GridT>
void ExplicitSolver<GridT>::integrate_nodes(const double* m_i, Vec<D>* v, Vec<D>* a, NodeV in_v) {
  const std::int64_t n = std::int64_t(grid_.nodes());
  const double floor = node_mass_floor_, dt = dt_;
  const bool momentum_in_v = in_v == NodeV::Momentum;
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    const double m = m_i[i];
    if (m > floor) {
      const Vec<D> a_i = a[i] / m;
      const Vec<D> v_i = momentum_in_v ? Vec<D>(v[i] / m) : v[i];
      v[i] = v_i + dt * a_i;  // p_i^{k+1} = p_i^k + f_i dt, divided by m_i
      a[i] = a_i;
    } else if (!v[i].isZero() || !a[i].isZero()) {  // keep empty nodes at zero
      v[i].setZero();
      a[i].setZero();
    }
  }
}

template <Grid GridT>
void ExplicitSolver<GridT>::grid_remap() {
  ScopedTimer timer(timers_, timers_.id("grid_remap"));
  sum_shared(kRemap);
  fold_ghosts(kRemap);
  momentum_to_velocity(grid_.m.data(), grid_.v_remap.data());
  for (int f = 1; f < contact_.field_count(); ++f)
    momentum_to_velocity(contact_.field(f).m.data(), contact_.field(f).q.data());
  exchange_momentum(Exchange::Remap);
  apply_boundary(Exchange::Remap);
}

template <Grid GridT>
void ExplicitSolver<GridT>::momentum_to_velocity(const double* m, Vec<D>* field) {
  const std::int64_t n = std::int64_t(grid_.nodes());
  const double floor = node_mass_floor_;
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    if (m[i] > floor)
      field[i] /= m[i];
    else if (!field[i].isZero())
      field[i].setZero();  // keep empty nodes at zero
  }
}

/// Every field's velocities held where boundary conditions and rigid bodies prescribe them;
/// after grid_update also its accelerations, recording the forces on the supports.
template <Grid GridT>
void ExplicitSolver<GridT>::apply_boundary(Exchange on) {
  const bool update = on == Exchange::Update;
  if (update) {
    face_force_.fill(0.0);
    if (has_rigid_)
      for (auto& f : rigid_force_) f.setZero();
  }
  auto& v0 = on == Exchange::Remap ? grid_.v_remap : grid_.v;
  hold_nodes(grid_.m.data(), v0.data(), update ? grid_.a.data() : nullptr);
  for (int f = 1; f < contact_.field_count(); ++f) {
    auto& fd = contact_.field(f);
    hold_nodes(fd.m.data(), (on == Exchange::Remap ? fd.q : fd.v).data(),
               update ? fd.a.data() : nullptr);
  }
}

/// Holds one field's velocities (and with `acc`, grid_update's accelerations, also recording
/// the forces on the supports) where boundary conditions and rigid bodies prescribe them.
template <Grid GridT>
void ExplicitSolver<GridT>::hold_nodes(const double* m, Vec<D>* vel, Vec<D>* acc) {
  const bool record_force = acc != nullptr;  // grid_update: the forces on the supports
  // Record the force each face carries (before holding the velocities), then hold them.
  if (record_force) {
    auto record = [&](std::int64_t n, int face) {
      if constexpr (Core::kRanks)
        if (ranks_ && !ranks_->owns(n)) return;  // another rank counts it
      const int axis = face / 2;
      const double sign = (face % 2 == 0) ? -1.0 : 1.0;
      face_force_[face] += sign * m[n] * vel[n][axis] / dt_;
    };
    for (const auto& f : grid_.fixed_nodes()) record(f.node, f.face);
    for (const auto& f : grid_.slip_nodes()) record(f.node, f.face);
  }
  for (const auto& f : grid_.fixed_nodes()) {
    vel[f.node].setZero();
    if (acc) acc[f.node].setZero();
  }
  for (const auto& f : grid_.slip_nodes()) {
    vel[f.node][f.face / 2] = 0.0;
    if (acc) acc[f.node][f.face / 2] = 0.0;
  }
  if constexpr (kGhosts)
    for (const auto& g : grid_.ghost_nodes()) {  // B-spline grids: the mirror images
      if (m[g.node] == 0) continue;
      vel[g.node] = g.mirror < 0 ? Vec<D>::Zero() : grid_.reflect(g, vel[g.mirror]);
      if (acc) acc[g.node] = g.mirror < 0 ? Vec<D>::Zero() : grid_.reflect(g, acc[g.mirror]);
    }
  if (!has_rigid_) return;
  // Rigid bodies, serially (a few nodes; the force sums stay in node order).
  const std::int64_t n = std::int64_t(grid_.nodes());
  for (std::int64_t i = 0; i < n; ++i) {
    const int mark = grid_.rigid[i];
    if (mark == 0 || m[i] <= node_mass_floor_) continue;
    const std::uint32_t body = marked_body_[mark - 1];
    const Vec<D>& vb = rigid_velocity_[body];
    const std::uint8_t held = rigid_held_[body];  // the other components slip
    bool book = record_force;
    if constexpr (Core::kRanks)
      if (ranks_ && !ranks_->owns(i)) book = false;  // another rank counts it
    for (int a = 0; a < D; ++a) {
      if (!(held >> a & 1)) continue;
      if (book)  // what the body pushes back; its work on the material
        book_rigid_force(int(body), a, m[i] * (vel[i][a] - vb[a]) / dt_);
      if (acc) acc[i][a] += (vb[a] - vel[i][a]) / dt_;
      vel[i][a] = vb[a];
    }
  }
}

}  // namespace mpm
