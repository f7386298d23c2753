#pragma once
// Stress update (000, eqs. 12-15): velocity gradient from the grid (in axisymmetry with the
// hoop rate v_r / r), then the material update once per block of particles of one material.
// When moving, positions advance with the grid velocity (000, eqs. 7, 9) in the same pass.
#include <omp.h>

#include <algorithm>

#include "mpm/solver/explicit/explicit_solver.hpp"

namespace mpm {

template <Grid GridT>
void ExplicitSolver<GridT>::update_stress(const std::vector<Vec<D>>& v_grad, Positions positions) {
  ScopedTimer timer(timers_, timers_.id(positions == Positions::Move ? "stress_move" : "stress"));
  const ParticleView<D> p = view<D>(particles_);
  material_ = p.material;
  const int nchunks = binning_.chunk_count();
  std::vector<ChunkSums> stats(nchunks);
  const bool remapped = &v_grad == &grid_.v_remap;  // MUSL: the fields' remapped velocities
  if (contact_.active()) {
#pragma omp parallel for schedule(dynamic, 1)
    for (int ch = 0; ch < nchunks; ++ch)
      stress_chunk<true>(p, ch, v_grad.data(), positions, remapped, stats[ch]);
  } else {
#pragma omp parallel for schedule(dynamic, 1)
    for (int ch = 0; ch < nchunks; ++ch)
      stress_chunk<false>(p, ch, v_grad.data(), positions, remapped, stats[ch]);
  }
  finish(stats, positions == Positions::Move ? kStresses | kPositions : kStresses);
}

/// The stress update of the particles of chunk ch from the grid velocities vg_i (flattened:
/// every call but the material update's is inlined into its loop); with contact (C), the
/// particles of bodies in contact take their fields' velocities (remapped: MUSL's).
template <Grid GridT>
template <bool C>
[[gnu::flatten]] void ExplicitSolver<GridT>::stress_chunk(const ParticleView<D>& p, int ch,
                                                          const Vec<D>* vg_i, Positions positions,
                                                          bool remapped, ChunkSums& s) {
  StressScratch& scr = *scratch_[omp_get_thread_num()];
  const Vec<D>* v_i = grid_.v.data();
  const auto& bins = binning_.bins();
  const auto& chunks = binning_.chunks();
  const double dt = dt_;
  const bool axi = axisymmetric_, move = positions == Positions::Move;
  PendingBlock pb;
  for (std::uint32_t bi = chunks[ch].bin_begin; bi < chunks[ch].bin_end; ++bi) {
    const Bin& bin = bins[bi];
    std::int64_t nodes[NMAX], other[NMAX];
    const int nn = grid_.cell_nodes(bin.key, nodes);
    Vec<D> vg_c[NMAX], v_c[NMAX];
    for (int c = 0; c < nn; ++c) {
      vg_c[c] = vg_i[nodes[c]];
      if (move) v_c[c] = v_i[nodes[c]];
    }
    const double h_cell = grid_.cell_size(bin.key);
    for (std::uint32_t i = bin.begin; i < bin.end; ++i) {
      if (p.material[i] >= kRebarNode) [[unlikely]] {  // rigid particles and rebar nodes
        if (move) move_unstressed(p, i, bin.key, nodes, nn, C ? nullptr : v_c, s);
        continue;
      }
      const auto [key, xi, home, nk, nd] = locate_in_bin(bin.key, nodes, nn, p.x[i], other);
      double N[NMAX];
      Vec<D> G[NMAX];
      grid_.shape(key, xi, N, G);
      // Velocity gradient L = sum_i v_i (x) G_ip (000, eqs. 12-13 use its parts).
      Mat<D> L = Mat<D>::Zero();
      Vec<D> vbar = Vec<D>::Zero();
      double v_r = 0;
      // Nodal velocities cached for the particle: its bin's, or its body's field's (contact).
      bool cached = home;
      const Vec<D>*vg_h = vg_c, *v_h = v_c;
      Vec<D> vg_f[C ? NMAX : 1], v_f[C ? NMAX : 1], vg_o[NMAX], v_o[NMAX];
      if constexpr (C)
        if (const int f = contact_.field_of(p.body[i])) {
          const auto& fd = contact_.field(f);
          for (int c = 0; c < nk; ++c) {
            vg_f[c] = remapped ? fd.q[nd[c]] : fd.v[nd[c]];
            v_f[c] = fd.v[nd[c]];
          }
          cached = true, vg_h = vg_f, v_h = v_f;
        }
      if (!cached) {  // off its bin's cell (or a graded cell's other nodes): gathered here
        for (int c = 0; c < nk; ++c) vg_o[c] = vg_i[nd[c]];
        if (move)
          for (int c = 0; c < nk; ++c) v_o[c] = v_i[nd[c]];
        vg_h = vg_o, v_h = v_o;
      }
      // One pass per sum, without a test inside: the compiler keeps each in registers.
      for (int c = 0; c < nk; ++c) L.noalias() += vg_h[c] * G[c].transpose();
      if (move)
        for (int c = 0; c < nk; ++c) vbar += N[c] * v_h[c];
      if (axi)
        for (int c = 0; c < nk; ++c) v_r += N[c] * vg_h[c][0];
      if (p.strain) p.strain[i] += dt * L.diagonal();  // for splitting (004, eq. 23)
      if constexpr (kAffine)
        if (p.C) {  // APIC: C_p = B_p D_p^-1 from the velocities v_p came from (Jiang 2015)
          Vec<D> W[NMAX];
          grid_.affine_weights(key, xi, N, G, W);
          Mat<D> Cp = Mat<D>::Zero();
          for (int c = 0; c < nk; ++c) Cp.noalias() += vg_h[c] * W[c].transpose();
          p.C[i] = Cp;
        }
      if (pb.ends_before(i, p.material[i], h_cell)) {
        stress_block(p, pb, scr, s);
        pb.restart(i, p.material[i], h_cell);
      }
      scr.L[pb.k].setZero();
      scr.L[pb.k].template topLeftCorner<D, D>() = L;
      if (axi) scr.L[pb.k](2, 2) = v_r / p.x[i][0];  // hoop rate
      ++pb.k;
      if (move) {
        p.x[i] += dt * vbar;  // (000, eq. 7)
        s.add_motion(p, i);
        track_move(p.x[i], i, bin.key, s);
      }
    }
  }
  stress_block(p, pb, scr, s);
}

/// Rigid particles advance with their own velocity; rebar nodes carry no stress (their
/// elements do: rebar_forces.hpp) and advance with the grid velocity (000, eq. 7), from their
/// body's field with contact.
template <Grid GridT>
void ExplicitSolver<GridT>::move_unstressed(const ParticleView<D>& p, std::uint32_t i,
                                            std::int64_t bin_key, const std::int64_t* nodes, int nn,
                                            const Vec<D>* v_c, ChunkSums& s) {
  if (rigid(i)) {
    p.x[i] += dt_ * p.v[i];
    track_move(p.x[i], i, bin_key, s);
    return;
  }
  std::int64_t other[NMAX];
  const auto [key, xi, home, nk, nd] = locate_in_bin(bin_key, nodes, nn, p.x[i], other);
  double N[NMAX];
  grid_.values(key, xi, N);
  const Vec<D>* v_i = grid_.v.data();
  if (contact_.active())
    if (const int f = contact_.field_of(p.body[i])) v_i = contact_.field(f).v.data();
  Vec<D> vbar = Vec<D>::Zero();
  for (int c = 0; c < nk; ++c) vbar += N[c] * (home && v_c ? v_c[c] : v_i[nd[c]]);
  p.x[i] += dt_ * vbar;  // (000, eq. 7)
  s.add_motion(p, i);
  track_move(p.x[i], i, bin_key, s);
}

/// The material update of the pending block (then empty), its internal energy and stable
/// steps into s, and the first fault.
template <Grid GridT>
void ExplicitSolver<GridT>::stress_block(const ParticleView<D>& p, PendingBlock& pb,
                                         StressScratch& scr, ChunkSums& s) const {
  if (pb.k == 0) return;
  const MaterialBlock blk = update_block(pb, p, scr);
  // In registers, not through s: the block's internal energy, and its fastest signal
  // (min_j h / s_j is h / max_j s_j exactly: a division is monotone, one is enough).
  double internal = 0, fastest = 0;
  for (int j = 0; j < pb.k; ++j) {
    const std::uint32_t i = pb.i0 + j;
    internal += p.m[i] * p.e[i];
    fastest = std::max(fastest, scr.c[j] + p.v[i].norm());
  }
  s.internal += internal;
  s.dt_min = std::min(s.dt_min, pb.h / fastest);
  if (blk.fault_index >= 0 && s.fault < 0) {
    s.fault = pb.i0 + blk.fault_index;
    s.cause = blk.fault == PointFault::VolumeInverted
                  ? "its volume became non-positive (1 + tr(D) dt <= 0)"
                  : "its stress or energy is not finite";
  }
  pb.k = 0;
}

}  // namespace mpm
