#pragma once
// Contact between bodies (004, section 5.4; Bardenhagen et al. 2001; Huang et al. 2011; Ma,
// Zhang & Huang 2010): every body of a [[contact]] pair carries its own velocity field, and at
// a node that two fields a and b share their momenta are exchanged by an impulse J on a and -J
// on b, so that total momentum is kept to round-off.
//
// Derivation. With reduced mass m_ab = m_a m_b / (m_a + m_b) and relative velocity
// w = v_a - v_b, the impulse -m_ab w gives both fields their centre-of-mass velocity (what
// one common field would hold). Contact keeps its normal part and Coulomb's share of the rest:
// with one unit normal n out of a into b, shared by both fields, the fields approach when
// w.n > 0, and then
//   J_n = -m_ab (w.n) n,   J_t = -m_ab (w - (w.n) n), scaled down to |J_t| <= mu |J_n|.
// The node's kinetic energy changes by J.w + |J|^2 / (2 m_ab) <= 0 (J_t is at most the
// sticking impulse): the exchange itself never adds energy. n is the mass gradient
// sum_p m_p grad N_i(x_p) of the field where it is steeper (out of a, or minus b's): at a
// corner of one body on a face of the other that is the face's normal, where an average
// would tilt it and push a frictionless block along the face. A pair may take the normal from
// one body instead (`normal = "<body>"`: a smooth penetrator's surface, whose normal a
// damaged, ragged target would tilt, dragging a frictionless shank through its hole) or from
// the difference of the two gradients (`normal = "average"`).
// Energy is gained when the velocities the stress sees and those the particles carry
// disagree (measured: two bars rebounding with 13% more energy, friction 13% too weak), so
// the first exchange of a step decides which pairs touch at each node and the second applies
// the same law at exactly those nodes, whatever the sign of w.n there:
// - USL and MUSL decide after the grid update, on the trial velocities v + f dt / m (where
//   the impulse needed to hold them would pull, they separate). The impulse changes the
//   velocities and, as J / (m dt), the accelerations the particles take (000, eq. 8), so
//   particle velocities, positions and USL's strain rate follow one field. MUSL's remapped
//   velocities (its strain rate) are another projection of the same motion: they get the
//   impulse at the nodes held after the update; releasing a node there that the update held
//   gave the stress a field the particles never had.
// - USF decides on the grid velocities before the stress; the update then holds those nodes.
//   The particles' accelerations are taken against the corrected velocities, so that
//   impulse reaches them too.
// The gap check: two fields touch at a node when their centres there, sum_p m_p N_i x_p / m_i,
// are closer than the pair's `gap` (1.5 cells by default) along n; without it
// bodies a cell apart would already push on each other (Huang et al. 2011). Touching bodies
// put those centres 2/3 to 1 cell apart, by how they share the node (touching_gap), so one
// number either misses some touching nodes or lets bodies apart push. With `separation` the
// pair compares the centres' distance with the touching one for the fields' shares of the
// node's volume, sum_p V_p N_i: the estimated distance of the surfaces. Both count in cells of
// the node (GradedGrid::node_cell_size: the largest cell its shape function spans), since the
// centres of touching bodies lie that node's cells apart; in the finest level's cells a
// coarser level's touching nodes went free and bodies passed each other there.
// Symmetry. A slip face is a mirror: the body goes on as its image beyond it, so the mass
// gradient at the face's nodes has no component across it. The particles of one side alone
// put one there, as large as at a free surface: the normal on the plane tilted, the held
// velocity kept only part of the impulse, and a half model pushed 55% off the whole model's
// half (test_contact_symmetry.cpp; now to round-off). In axisymmetry the gradient is the
// section's, sum_p (m_p / r_p) grad N_i: a particle's mass per radian grows with its radius,
// and inside a uniform body that gradient, -rho A_i e_r, tilts the normal toward the axis by
// about the cell over the node's radius (two bars meeting flat in a sleeve at 50 m/s threw
// particles sideways at 47 m/s with the slip faces mirrored, 53 m/s without; now at 1e-12 m/s).
#include <omp.h>

#include <algorithm>

#include "mpm/solver/explicit/explicit_solver.hpp"

namespace mpm {

/// The slip faces are mirrors: no body's mass gradient crosses one at its nodes.
template <Grid GridT>
void ExplicitSolver<GridT>::mirror_slip_normals() {
  for (int f = 1; f < contact_.field_count(); ++f) {
    Vec<D>* g = contact_.field(f).g.data();
    for (const auto& s : grid_.slip_nodes()) g[s.node][s.face / 2] = 0.0;
  }
}

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
  const double* V_f[kMaxF];
  m_f[0] = grid_.m.data();
  v_f[0] = on == Exchange::Remap ? grid_.v_remap.data() : grid_.v.data();
  a_f[0] = grid_.a.data();
  g_f[0] = x_f[0] = nullptr;  // the common field only ever sticks
  V_f[0] = nullptr;
  for (int f = 1; f < F; ++f) {
    auto& fd = contact_.field(f);
    m_f[f] = fd.m.data();
    v_f[f] = on == Exchange::Remap ? fd.q.data() : fd.v.data();
    a_f[f] = fd.a.data();
    g_f[f] = fd.g.data();
    x_f[f] = fd.x.data();
    V_f[f] = fd.V.data();
  }
  const bool update = on == Exchange::Update;  // accelerations and forces follow
  // The step's first exchange decides which pairs touch at each node, the second follows.
  const bool decide = on == Exchange::Velocity || (update && scheme_ != Scheme::USF);
  const bool follow = !decide;
  if (decide) mirror_slip_normals();             // the step's gradients are complete
  std::uint64_t* held = contact_.held().data();  // per node: pairs in contact (bits)
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
      if (k < 2) {
        if (decide) held[i] = 0;
        continue;
      }
      std::uint64_t state = follow ? held[i] : 0;
      // Pairs of the fields present, in field order (a Gauss-Seidel sweep over the pairs);
      // bit s of the node's state: the s-th pair was in contact after the update.
      int s = -1;
      for (int x = 0; x < k; ++x)
        for (int y = x + 1; y < k; ++y) {
          ++s;
          const int a = at[x], b = at[y];
          const double ma = m_f[a][i], mb = m_f[b][i];
          const double m_ab = ma * mb / (ma + mb);  // reduced mass
          const Vec<D> w = v_f[a][i] - v_f[b][i];   // velocity of a relative to b
          const double mu = contact_.friction(a, b);
          Vec<D> J;  // impulse on field a (and -J on b), kg m/s
          if (mu < 0) {
            J = -m_ab * w;  // not a pair: the fields stick
          } else {
            const Vec<D>& g_a = g_f[a][i];
            const Vec<D>& g_b = g_f[b][i];
            const int from = contact_.normal_from(a, b);
            Vec<D> nrm = from == a   ? g_a
                         : from == b ? Vec<D>(-g_b)
                         : from == ContactFields<D>::kAverage
                             ? Vec<D>(g_a - g_b)
                             : (g_a.squaredNorm() >= g_b.squaredNorm() ? g_a : Vec<D>(-g_b));
            const double len = nrm.norm();
            if (!(len > 0)) continue;
            nrm /= len;
            const double w_n = w.dot(nrm);
            if (follow && s < 64) {
              if (!(state >> s & 1)) continue;  // free after the update: free
            } else {
              if (w_n <= 0) continue;  // separating: free
              const Vec<D> gap = x_f[b][i] / mb - x_f[a][i] / ma;
              const double sep = contact_.separation(a, b);
              const double cell = grid_.node_cell_size(i);
              if (sep < 0) {
                if (gap.dot(nrm) > contact_.touch(a, b) * cell) continue;  // apart: free
              } else {
                const double Va = V_f[a][i], Vb = V_f[b][i];
                const double touching = touching_gap(Va / (Va + Vb));
                if (gap.dot(nrm) > (touching + sep) * cell) continue;  // apart: free
              }
              if (decide && s < 64) state |= std::uint64_t(1) << s;
            }
            const Vec<D> J_n = -m_ab * w_n * nrm;
            Vec<D> J_t = -m_ab * (w - w_n * nrm);  // sticking impulse
            const double j_t = J_t.norm(), cap = mu * m_ab * std::abs(w_n);
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
      if (decide) held[i] = state;
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
