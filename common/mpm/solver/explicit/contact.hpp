#pragma once
// Contact between bodies (004, section 5.4; Bardenhagen et al. 2001; Huang et al. 2011): at a
// node that two velocity fields share, the normal is the difference of their mass gradients;
// where the fields approach along it their normal velocities are made equal and the
// tangential difference is removed as far as Coulomb friction allows; where they separate
// they stay free. Fields that are not a [[contact]] pair stick. Each correction is an impulse
// between two fields only, so total momentum is kept to round-off.
#include <omp.h>

#include <algorithm>

#include "mpm/solver/explicit/explicit_solver.hpp"

namespace mpm {

template <Grid GridT>
void ExplicitSolver<GridT>::exchange_momentum(Exchange on) {
  if (!contact_.active()) return;
  ScopedTimer timer(timers_, timers_.id("contact"));
  constexpr int kMaxF = ContactFields<D>::kMaxFields;
  const int F = contact_.field_count();
  // Each field's node arrays: mass, velocity (or remapped velocity), acceleration, gradient.
  const double* m_f[kMaxF];
  Vec<D>* v_f[kMaxF];
  Vec<D>* a_f[kMaxF];
  const Vec<D>* g_f[kMaxF];
  const Vec<D>* x_f[kMaxF];
  m_f[0] = grid_.m.data();
  v_f[0] = on == Exchange::Remap ? grid_.v_remap.data() : grid_.v.data();
  a_f[0] = grid_.a.data();
  g_f[0] = x_f[0] = nullptr;  // the common field only ever sticks
  for (int f = 1; f < F; ++f) {
    auto& fd = contact_.field(f);
    m_f[f] = fd.m.data();
    v_f[f] = on == Exchange::Remap ? fd.q.data() : fd.v.data();
    a_f[f] = fd.a.data();
    g_f[f] = fd.g.data();
    x_f[f] = fd.x.data();
  }
  // Two fields touch at a node when their centres there are closer than two thirds of a
  // cell: the distance of the centres of two half-spaces that meet at the node, under the
  // linear shape functions (Huang et al. 2011 check the gap for the same reason: without it
  // bodies a cell apart would already push on each other).
  const double touch = 2.0 / 3.0 * grid_.min_cell_size();
  const bool update = on == Exchange::Update;  // accelerations and forces follow the velocities
  const double floor = node_mass_floor_, dt = dt_;
  const std::int64_t n = std::int64_t(grid_.nodes());
  // Forces summed per block of nodes, then over blocks in order: the same bits on any threads.
  constexpr std::int64_t kNodes = 4096;
  const std::int64_t blocks = (n + kNodes - 1) / kNodes;
  const std::size_t P = contact_.force().size();
  std::vector<Vec<D>> block_force(update ? std::size_t(blocks) * P : 0, Vec<D>::Zero());
#pragma omp parallel for schedule(static)
  for (std::int64_t blk = 0; blk < blocks; ++blk) {
    for (std::int64_t i = blk * kNodes; i < std::min(n, (blk + 1) * kNodes); ++i) {
      int at[kMaxF], k = 0;
      for (int f = 0; f < F; ++f)
        if (m_f[f][i] > floor) at[k++] = f;
      // Pairs of the fields present, in field order (a Gauss-Seidel sweep over the pairs).
      for (int x = 0; x < k; ++x)
        for (int y = x + 1; y < k; ++y) {
          const int a = at[x], b = at[y];
          const double ma = m_f[a][i], mb = m_f[b][i];
          const double m_ab = ma * mb / (ma + mb);  // reduced mass
          const Vec<D> w = v_f[a][i] - v_f[b][i];   // velocity of a relative to b
          const double mu = contact_.friction(a, b);
          Vec<D> J;  // impulse on field a (and -J on b), kg m/s
          if (mu < 0) {
            J = -m_ab * w;  // not a pair: the fields stick
          } else {
            // sum_p m_p grad N_i(x_p) points out of a body at its surface nodes. The normal out
            // of body a into body b is that of the field with the steeper gradient: at a
            // corner of one body against a face of the other, the face's (the average of the
            // two would tilt it); inside a body that another one enters, the intruder's.
            const Vec<D>& g_a = g_f[a][i];
            const Vec<D>& g_b = g_f[b][i];
            Vec<D> nrm = g_a.squaredNorm() >= g_b.squaredNorm() ? g_a : Vec<D>(-g_b);
            const double len = nrm.norm();
            if (!(len > 0)) continue;
            nrm /= len;
            const double w_n = w.dot(nrm);
            if (w_n <= 0) continue;  // separating: free
            const Vec<D> gap = x_f[b][i] / mb - x_f[a][i] / ma;
            if (gap.dot(nrm) > touch) continue;  // apart: free
            const Vec<D> J_n = -m_ab * w_n * nrm;
            Vec<D> J_t = -m_ab * (w - w_n * nrm);  // sticking impulse
            const double j_t = J_t.norm(), cap = mu * m_ab * w_n;
            if (j_t > cap) J_t *= cap / j_t;  // Coulomb: |J_t| <= mu |J_n|
            J = J_n + J_t;
          }
          v_f[a][i] += J / ma;
          v_f[b][i] -= J / mb;
          if (update) {
            a_f[a][i] += J / (ma * dt);
            a_f[b][i] -= J / (mb * dt);
            if (const int pr = contact_.pair(a, b); pr >= 0) block_force[blk * P + pr] += J / dt;
          }
        }
    }
  }
  if (!update) return;
  for (auto& f : contact_.force()) f.setZero();
  for (std::int64_t blk = 0; blk < blocks; ++blk)
    for (std::size_t pr = 0; pr < P; ++pr)
      for (int a = 0; a < D; ++a)
        contact_.force()[pr][a] += contact_.sign(int(pr)) * block_force[blk * P + pr][a];
}

}  // namespace mpm
