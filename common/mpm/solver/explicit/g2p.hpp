#pragma once
// Grid to particle: velocity (000, eqs. 8, 10), position when moving (eqs. 7, 9), and for
// MUSL the remapped momentum m_p v_p back to the grid (eq. 11), a scatter (scatter.hpp).
// Rigid particles keep their velocity and, when moving, advance with it.
#include <omp.h>

#include <algorithm>

#include "mpm/solver/explicit/explicit_solver.hpp"

namespace mpm {

template <Grid GridT>
template <typename ExplicitSolver<GridT>::G2pMode M>
void ExplicitSolver<GridT>::g2p() {
  constexpr bool kRemapped = M == G2pMode::Remap, kMove = M == G2pMode::Move;
  ScopedTimer timer(timers_, timers_.id(kRemapped                ? "g2p_remap"
                                        : kMove                  ? "g2p_move"
                                        : M == G2pMode::Velocity ? "g2p"
                                                                 : "g2p_pic"));
  if (contact_.active())
    gather_from_grid<M, true>();
  else
    gather_from_grid<M, false>();
}

/// The particle update of g2p; with contact (C), the particles of the bodies in contact read
/// their bodies' fields (and remap into them).
template <Grid GridT>
template <typename ExplicitSolver<GridT>::G2pMode M, bool C>
void ExplicitSolver<GridT>::gather_from_grid() {
  constexpr bool kRemapped = M == G2pMode::Remap, kMove = M == G2pMode::Move;
  constexpr bool kPic = M == G2pMode::Pic;
  const ParticleView<D> p = view<D>(particles_);
  material_ = p.material;
  const Vec<D>* a_i = grid_.a.data();
  const Vec<D>* v_i = grid_.v.data();
  const auto& bins = binning_.bins();
  const int nchunks = binning_.chunk_count();
  const double dt = dt_;
  std::vector<ChunkSums> stats(std::max(nchunks, omp_get_max_threads()));

  auto move_rigid = [&](std::uint32_t i, ChunkSums& s, std::int64_t bin_key) {
    if constexpr (kMove) {
      p.x[i] += dt * p.v[i];
      track_move(p.x[i], i, bin_key, s);
    }
  };
  // One particle on its own: update (when first visited) and remap into a target. The bodies
  // are flattened (every call inlined), as the kernel's hot loops.
  auto particle_body = [&] [[gnu::flatten]] (std::uint32_t i, const Target& t, bool first_visit,
                                             int unit) {
    std::int64_t key, nd[NMAX];
    Vec<D> xi;
    grid_.locate(p.x[i], key, xi);
    if (first_visit && rigid(i)) {
      move_rigid(i, stats[unit], key);
      return;
    }
    if (rigid(i)) return;
    const int nk = grid_.cell_nodes(key, nd);
    double N[NMAX];
    if constexpr (C)
      if (const int f = contact_.field_of(p.body[i]))
        return advance_in_field<M>(p, i, f, key, xi, nd, nk, first_visit, kRemapped, stats[unit],
                                   key);
    if (first_visit)
      advance_particle<M>(p, i, key, xi, nd, nk, nullptr, nullptr, N, stats[unit], key,
                          stats[unit].leapfrog_kinetic);
    else
      grid_.values(key, xi, N);
    if constexpr (kRemapped) {
      const Vec<D> mv = p.m[i] * p.v[i];
      for (int c = 0; c < nk; ++c) t.q[nd[c] - t.offset] += N[c] * mv;
    }
  };
  // One bin with its cell's nodal values cached.
  auto bin_body = [&] [[gnu::flatten]] (int ch, std::uint32_t bi, const Target& t,
                                        std::vector<std::uint32_t>* strays) {
    ChunkSums& s = stats[ch];
    const Bin& bin = bins[bi];
    const int layer = grid_.layer(bin.key);
    std::int64_t nodes[NMAX], other[NMAX];
    const int nn = grid_.cell_nodes(bin.key, nodes);
    Vec<D> a_c[NMAX], v_c[NMAX], q_c[NMAX];
    for (int c = 0; c < nn; ++c) {
      a_c[c] = a_i[nodes[c]];
      if constexpr (kMove || kPic) v_c[c] = v_i[nodes[c]];
      q_c[c].setZero();
    }
    double leapfrog = 0;  // the bin's m v(k-1/2).v(k+1/2) / 2, in a register
    // Uniform and sparse 3D cells: the particles in the bin's cell sum the corners' values
    // as vectors (advance_in_cell).
    CornerVectors cv;
    if constexpr (kTrilinear) cv.set(a_c, kMove || kPic ? v_c : nullptr);
    for (std::uint32_t i = bin.begin; i < bin.end; ++i) {
      if (rigid(i)) {
        move_rigid(i, s, bin.key);
        continue;
      }
      const auto [key, xi, home, nk, nd] = locate_in_bin(bin, nodes, nn, p.x[i], other);
      double N[NMAX];
      if constexpr (C)
        if (const int f = contact_.field_of(p.body[i])) {
          const bool remap = kRemapped && (home || !strays || grid_.layer(key) == layer);
          advance_in_field<M>(p, i, f, key, xi, nd, nk, true, remap, s, bin.key);
          if (kRemapped && !remap) strays->push_back(i);
          continue;
        }
      if (kTrilinear && home)
        advance_in_cell<M>(p, i, key, xi, cv, N, s, bin.key, leapfrog);
      else
        advance_particle<M>(p, i, key, xi, nd, nk, home ? a_c : nullptr, home ? v_c : nullptr, N, s,
                            bin.key, leapfrog);
      if constexpr (kRemapped) {
        const Vec<D> mv = p.m[i] * p.v[i];
        if (home) {
          for (int c = 0; c < nk; ++c) q_c[c] += N[c] * mv;
        } else if (!strays || grid_.layer(key) == layer) {
          for (int c = 0; c < nk; ++c) t.q[nd[c] - t.offset] += N[c] * mv;
        } else {
          strays->push_back(i);
        }
      }
    }
    s.leapfrog_kinetic += leapfrog;
    if constexpr (kRemapped)
      for (int c = 0; c < nn; ++c) t.q[nodes[c] - t.offset] += q_c[c];
  };

  if constexpr (kRemapped) {
    scatter(kRemap, bin_body, particle_body);
  } else {  // a gather: any chunk on any thread
    const auto& chunks = binning_.chunks();
    const Target none{nullptr, nullptr, nullptr, nullptr, 0};
#pragma omp parallel for schedule(dynamic, 1)
    for (int ch = 0; ch < nchunks; ++ch)
      for (std::uint32_t bi = chunks[ch].bin_begin; bi < chunks[ch].bin_end; ++bi)
        bin_body(ch, bi, none, nullptr);
  }
  finish(stats, kMove ? kVelocities | kPositions : kVelocities);
}

/// The velocity (and when moving, position) update of particle i, in cell `key` at local
/// coordinates xi, from the nodal values at the nodes nd of its cell (a_c, v_c: cached
/// copies, or null to read the grid); returns its shape function values in N for the remap,
/// and adds m v(k-1/2).v(k+1/2) / 2 to `leapfrog` (a sum of s, or the caller's in a register).
template <Grid GridT>
template <typename ExplicitSolver<GridT>::G2pMode M>
void ExplicitSolver<GridT>::advance_particle(const ParticleView<D>& p, std::uint32_t i,
                                             std::int64_t key, const Vec<D>& xi,
                                             const std::int64_t* nd, int nk, const Vec<D>* a_c,
                                             const Vec<D>* v_c, double* N, ChunkSums& s,
                                             std::int64_t bin_key, double& leapfrog) const {
  constexpr bool kMove = M == G2pMode::Move, kPic = M == G2pMode::Pic;
  grid_.values(key, xi, N);
  Vec<D> a_p = Vec<D>::Zero(), vbar = Vec<D>::Zero();
  for (int c = 0; c < nk; ++c) {
    if constexpr (!kPic) a_p += N[c] * (a_c ? a_c[c] : grid_.a[nd[c]]);
    if constexpr (kMove || kPic) vbar += N[c] * (v_c ? v_c[c] : grid_.v[nd[c]]);
  }
  update_particle<M>(p, i, a_p, vbar, s, bin_key, leapfrog);
}

/// Uniform and sparse 3D cells: advance_particle for a particle in its bin's cell, the sums
/// over the corners as vectors (x, y, z, 0) a corner at a time (lanes.hpp).
template <Grid GridT>
template <typename ExplicitSolver<GridT>::G2pMode M>
[[gnu::always_inline]] inline void ExplicitSolver<GridT>::advance_in_cell(
    const ParticleView<D>& p, std::uint32_t i, std::int64_t key, const Vec<D>& xi,
    const CornerVectors& cv, double* N, ChunkSums& s, std::int64_t bin_key,
    double& leapfrog) const {
  if constexpr (kTrilinear) {
    constexpr bool kMove = M == G2pMode::Move, kPic = M == G2pMode::Pic;
    grid_.values(key, xi, N);
    lanes::V4 a{}, v{};
    for (int c = 0; c < 8; ++c) {
      if constexpr (!kPic) a += N[c] * cv.a[c];
      if constexpr (kMove || kPic) v += N[c] * cv.v[c];
    }
    update_particle<M>(p, i, Vec<D>(a[0], a[1], a[2]), Vec<D>(v[0], v[1], v[2]), s, bin_key,
                       leapfrog);
  }
}

/// Particle i's velocity (and position) from its interpolated grid acceleration a_p and
/// velocity vbar (advance_particle's sums, or a trilinear bin's: gather_from_grid).
template <Grid GridT>
template <typename ExplicitSolver<GridT>::G2pMode M>
[[gnu::always_inline]] inline void ExplicitSolver<GridT>::update_particle(
    const ParticleView<D>& p, std::uint32_t i, const Vec<D>& a_p, const Vec<D>& vbar, ChunkSums& s,
    std::int64_t bin_key, double& leapfrog) const {
  constexpr bool kMove = M == G2pMode::Move, kPic = M == G2pMode::Pic;
  const double dt = dt_;
  const Vec<D> v_old = p.v[i];
  Vec<D> v_new;
  if constexpr (kPic)
    v_new = vbar;  // APIC: the grid's velocity; its affine part C_p in update_stress
  else
    v_new = v_old + dt * a_p;  // (000, eq. 8)
  p.v[i] = v_new;
  leapfrog += 0.5 * p.m[i] * v_old.dot(v_new);
  if (loads_) s.add_load_work(p, i, dt, gravity_, v_old);
  if constexpr (kMove) {
    p.x[i] += dt * vbar;  // (000, eq. 7)
    s.add_motion(p, i);
    track_move(p.x[i], i, bin_key, s);
  }
}

/// Particle i of a body in contact (field f, cell `key`, nodes nd): its update from its
/// field's nodal values when `advance`, its remapped momentum into the field when `remap`.
template <Grid GridT>
template <typename ExplicitSolver<GridT>::G2pMode M>
void ExplicitSolver<GridT>::advance_in_field(const ParticleView<D>& p, std::uint32_t i, int f,
                                             std::int64_t key, const Vec<D>& xi,
                                             const std::int64_t* nd, int nk, bool advance,
                                             bool remap, ChunkSums& s, std::int64_t bin_key) {
  auto& fd = contact_.field(f);
  double N[NMAX];
  if (advance) {
    Vec<D> a_f[NMAX], v_f[NMAX];
    for (int c = 0; c < nk; ++c) a_f[c] = fd.a[nd[c]], v_f[c] = fd.v[nd[c]];
    advance_particle<M>(p, i, key, xi, nd, nk, a_f, v_f, N, s, bin_key, s.leapfrog_kinetic);
  } else {
    grid_.values(key, xi, N);
  }
  if (remap) {
    const Vec<D> mv = p.m[i] * p.v[i];
    for (int c = 0; c < nk; ++c) fd.q[nd[c]] += N[c] * mv;
  }
}

}  // namespace mpm
