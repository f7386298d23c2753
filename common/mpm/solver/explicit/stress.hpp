#pragma once
// Stress update (000, eqs. 12-15): velocity gradient from the grid (in axisymmetry with the
// hoop rate v_r / r), then the material update once per block of particles of one material.
// When moving, positions advance with the grid velocity (000, eqs. 7, 9) in the same pass.
#include <omp.h>

#include <algorithm>

#include "mpm/solver/damage_average.hpp"
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
  if (!averaged_.empty()) damage_increment_.assign(p.n, 0.0);  // none where no update wrote
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
  if (!averaged_.empty()) average_damage();
}

/// The damage increments of the HJC materials with a damage_length, averaged over it and
/// added to their damage (damage_average.hpp): the damage of t^(n+1), which the next step's
/// strength and tension cut read.
template <Grid GridT>
void ExplicitSolver<GridT>::average_damage() {
  ScopedTimer timer(timers_, timers_.id("damage_average"));
  const ParticleView<D> p = view<D>(particles_);
  for (int mat : averaged_) {
    DamageAverageInput<D> in;
    in.n = p.n;
    in.x = p.x;
    in.m = p.m;
    in.material = p.material;
    in.mat = mat;
    in.length = materials_[mat].spec().hjc.damage_length;
    in.increment = damage_increment_.data();
    in.damage = p.damage;
    mpm::average_damage<D>(in, ranks_ ? &Comm::world() : nullptr, lattice_q_, lattice_m_);
  }
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
  bool rows = false;  // the pending block's gradients one component an array (a fused material)
  TrilinearBin tb;
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
    // Uniform and sparse 3D cells: the bin's particles still in its cell take their velocity
    // gradient and move velocity from trilinear_sums, a vector of particles at a time.
    const bool fast =
        kTrilinear && !C && !axi && !p.C && !p.strain && bin.end - bin.begin <= TrilinearBin::kMax;
    if (fast) trilinear_sums(p, bin, vg_c, move ? v_c : nullptr, tb);
    for (std::uint32_t i = bin.begin; i < bin.end; ++i) {
      if (p.material[i] >= kRebarNode) [[unlikely]] {  // rigid particles and rebar nodes
        if (move) move_unstressed(p, i, bin, nodes, nn, C ? nullptr : v_c, s);
        continue;
      }
      if (pb.ends_before(i, p.material[i], h_cell)) {
        stress_block(p, pb, scr, s, rows, move);
        pb.restart(i, p.material[i], h_cell);
        // The fused update reads the gradients as columns in place (3D; materials.cpp); the
        // composed one takes matrices.
        rows = D == 3 && materials_[pb.mat].fused();
      }
      Vec<D> vbar;
      double v_r = 0;
      if (const int j = int(i - bin.begin); fast && tb.home[j]) {
        if constexpr (kTrilinear)  // straight into the block's columns or matrices
          for (int r = 0; r < 3; ++r) {
            if (rows)
              for (int c = 0; c < 3; ++c) scr.L_rows[3 * r + c][pb.k] = tb.L[3 * r + c][j];
            else
              for (int c = 0; c < 3; ++c) scr.L[pb.k](r, c) = tb.L[3 * r + c][j];
            vbar[r] = tb.v[r][j];
          }
      } else {
        Mat<D> L;
        general_sums<C>(p, i, bin, nodes, nn, other, vg_i, v_c, vg_c, move, remapped, L, vbar, v_r);
        if (rows) {
          for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) scr.L_rows[3 * r + c][pb.k] = L(r, c);
        } else {
          scr.L[pb.k].setZero(), scr.L[pb.k].template topLeftCorner<D, D>() = L;
        }
      }
      if (axi) scr.L[pb.k](2, 2) = v_r / p.x[i][0];  // hoop rate
      ++pb.k;
      if (move) {             // (the block's kinetic energy and momentum: stress_block)
        p.x[i] += dt * vbar;  // (000, eq. 7)
        if (!fast) track_move(p.x[i], i, bin.key, s);
      }
    }
    if (fast && move) track_bin(p, bin, tb, s);
  }
  stress_block(p, pb, scr, s, rows, move);
}

/// Uniform and sparse 3D cells: the bin's particles' local coordinates in its cell (tb.x) and
/// whether they are still there (tb.home), whole vectors at a time; returns the particles.
/// Without Xi (the move's tracking) only whether.
/// Positions go one axis an array first: a bin holds about 8 particles, and the compiler's
/// vector loop over the particles' interleaved coordinates wanted more than a vector's worth
/// (the rest ran scalar). Lanes past the bin repeat its first particle. The test and xi are
/// CellLattice::in_cell's, in plain doubles (the compiler vectorises no Eigen vector built in
/// the loop).
template <Grid GridT>
template <bool Xi>
[[gnu::always_inline]] inline int ExplicitSolver<GridT>::cell_lanes(const ParticleView<D>& p,
                                                                    const Bin& bin,
                                                                    TrilinearBin& tb) const {
  const int n = int(bin.end - bin.begin), nv = TrilinearBin::lanes(n);
  if constexpr (kTrilinear) {
    const Vec<D>* x = p.x + bin.begin;
    for (int j = 0; j < nv; ++j)
      for (int a = 0; a < 3; ++a) tb.x[a][j] = x[j < n ? j : 0][a];
    double o[3], c[3];
    for (int a = 0; a < 3; ++a) o[a] = grid_.origin()[a], c[a] = bin.cell[std::size_t(a)];
    const double ih = grid_.inv_h();
#pragma omp simd
    for (int j = 0; j < nv; ++j) {
      bool in = true;
      for (int a = 0; a < 3; ++a) {
        const double r = (tb.x[a][j] - o[a]) * ih;
        in = in & (r >= c[a]) & (r < c[a] + 1.0);
        if constexpr (Xi) tb.x[a][j] = r - c[a];
      }
      tb.home[j] = in;
    }
  }
  return n;
}

/// Uniform and sparse 3D cells, after the move: a vector pass over the bin finds the particles
/// still in its cell (finite, in the domain and the window, in the bin: nothing to book), and
/// only the others go through track_move. Rigid particles and rebar nodes were tracked as they
/// moved (move_unstressed).
template <Grid GridT>
void ExplicitSolver<GridT>::track_bin(const ParticleView<D>& p, const Bin& bin, TrilinearBin& tb,
                                      ChunkSums& s) const {
  if constexpr (kTrilinear) {
    const int n = cell_lanes<false>(p, bin, tb);  // (the bin's sums are used: tb is free)
    for (int j = 0; j < n; ++j)
      if (const std::uint32_t i = bin.begin + std::uint32_t(j);
          !tb.home[j] && p.material[i] < kRebarNode)
        track_move(p.x[i], i, bin.key, s);
  }
}

/// The velocity gradient L = sum_i v_i (x) G_ip (000, eqs. 12-13 use its parts), the move
/// velocity sum_i N_ip v_i and (axisymmetric) the hoop rate's v_r of particle i from its cell's
/// nodes, with any shape functions; also its strain (graded grids) and APIC's C_p.
template <Grid GridT>
template <bool C>
[[gnu::always_inline]] inline void ExplicitSolver<GridT>::general_sums(
    const ParticleView<D>& p, std::uint32_t i, const Bin& bin, const std::int64_t* nodes, int nn,
    std::int64_t* other, const Vec<D>* vg_i, const Vec<D>* v_c, const Vec<D>* vg_c, bool move,
    bool remapped, Mat<D>& L, Vec<D>& vbar, double& v_r) {
  const double dt = dt_;
  const bool axi = axisymmetric_;
  const Vec<D>* v_i = grid_.v.data();
  const auto [key, xi, home, nk, nd] = locate_in_bin(bin, nodes, nn, p.x[i], other);
  double N[NMAX];
  Vec<D> G[NMAX];
  grid_.shape(key, xi, N, G);
  L.setZero();
  vbar.setZero();
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
}

/// Uniform and sparse 3D cells: which particles of a bin are still in its cell, and for those the
/// velocity gradient and (v given) the move velocity, a vector of particles at a time. With
/// trilinear weights w_a(0) = 1 - xi_a, w_a(1) = xi_a, column a of L = sum_c v_c (x) G_c is
/// the bilinear interpolation over the other two axes of the nodal velocity differences
/// across axis a, divided by h: 36 products a particle where the sum over the 8 nodes took 72.
template <Grid GridT>
void ExplicitSolver<GridT>::trilinear_sums(const ParticleView<D>& p, const Bin& bin,
                                           const Vec<D>* vg, const Vec<D>* v,
                                           TrilinearBin& tb) const {
  if constexpr (kTrilinear) {
    const int nv = TrilinearBin::lanes(cell_lanes<true>(p, bin, tb));
    // Corner c = bx + 2 by + 4 bz. Differences across x on the edges e = by + 2 bz, across y
    // on e = bx + 2 bz, across z on e = bx + 2 by.
    double dx[3][4], dy[3][4], dz[3][4];
    for (int e = 0; e < 4; ++e)
      for (int r = 0; r < 3; ++r) {
        const int lo = e & 1, hi = e >> 1;
        dx[r][e] = vg[2 * lo + 4 * hi + 1][r] - vg[2 * lo + 4 * hi][r];
        dy[r][e] = vg[lo + 4 * hi + 2][r] - vg[lo + 4 * hi][r];
        dz[r][e] = vg[lo + 2 * hi + 4][r] - vg[lo + 2 * hi][r];
      }
    const double ih = grid_.inv_h();
#pragma omp simd
    for (int j = 0; j < nv; ++j) {
      const double x1 = tb.x[0][j], y1 = tb.x[1][j], z1 = tb.x[2][j];
      const double x0 = 1.0 - x1, y0 = 1.0 - y1, z0 = 1.0 - z1;
      const double yz[4] = {y0 * z0, y1 * z0, y0 * z1, y1 * z1};
      const double xz[4] = {x0 * z0, x1 * z0, x0 * z1, x1 * z1};
      const double xy[4] = {x0 * y0, x1 * y0, x0 * y1, x1 * y1};
      for (int r = 0; r < 3; ++r) {
        tb.L[3 * r + 0][j] =
            ih * (yz[0] * dx[r][0] + yz[1] * dx[r][1] + yz[2] * dx[r][2] + yz[3] * dx[r][3]);
        tb.L[3 * r + 1][j] =
            ih * (xz[0] * dy[r][0] + xz[1] * dy[r][1] + xz[2] * dy[r][2] + xz[3] * dy[r][3]);
        tb.L[3 * r + 2][j] =
            ih * (xy[0] * dz[r][0] + xy[1] * dz[r][1] + xy[2] * dz[r][2] + xy[3] * dz[r][3]);
      }
    }
    if (!v) return;
#pragma omp simd
    for (int j = 0; j < nv; ++j) {  // (named weights: an array here kept the loop scalar)
      const double x1 = tb.x[0][j], y1 = tb.x[1][j], z1 = tb.x[2][j];
      const double x0 = 1.0 - x1, y0 = 1.0 - y1, z0 = 1.0 - z1;
      const double N0 = x0 * y0 * z0, N1 = x1 * y0 * z0, N2 = x0 * y1 * z0, N3 = x1 * y1 * z0,
                   N4 = x0 * y0 * z1, N5 = x1 * y0 * z1, N6 = x0 * y1 * z1, N7 = x1 * y1 * z1;
      for (int r = 0; r < 3; ++r)
        tb.v[r][j] = N0 * v[0][r] + N1 * v[1][r] + N2 * v[2][r] + N3 * v[3][r] + N4 * v[4][r] +
                     N5 * v[5][r] + N6 * v[6][r] + N7 * v[7][r];
    }
  }
}

/// Rigid particles advance with their own velocity; rebar nodes carry no stress (their
/// elements do: rebar_forces.hpp) and advance with the grid velocity (000, eq. 7), from their
/// body's field with contact.
template <Grid GridT>
void ExplicitSolver<GridT>::move_unstressed(const ParticleView<D>& p, std::uint32_t i,
                                            const Bin& bin, const std::int64_t* nodes, int nn,
                                            const Vec<D>* v_c, ChunkSums& s) {
  if (rigid(i)) {
    p.x[i] += dt_ * p.v[i];
    track_move(p.x[i], i, bin.key, s);
    return;
  }
  std::int64_t other[NMAX];
  const auto [key, xi, home, nk, nd] = locate_in_bin(bin, nodes, nn, p.x[i], other);
  double N[NMAX];
  grid_.values(key, xi, N);
  const Vec<D>* v_i = grid_.v.data();
  if (contact_.active())
    if (const int f = contact_.field_of(p.body[i])) v_i = contact_.field(f).v.data();
  Vec<D> vbar = Vec<D>::Zero();
  for (int c = 0; c < nk; ++c) vbar += N[c] * (home && v_c ? v_c[c] : v_i[nd[c]]);
  p.x[i] += dt_ * vbar;  // (000, eq. 7)
  s.add_motion(p, i);
  track_move(p.x[i], i, bin.key, s);
}

/// The material update of the pending block (then empty), its internal energy and stable
/// steps into s, and the first fault; with `motion` also its kinetic energy and momentum. Its
/// velocity gradients are in scr.L_rows when `rows`, else in scr.L.
template <Grid GridT>
void ExplicitSolver<GridT>::stress_block(const ParticleView<D>& p, PendingBlock& pb,
                                         StressScratch& scr, ChunkSums& s, bool rows,
                                         bool motion) const {
  if (pb.k == 0) return;
  const MaterialBlock blk = update_block(
      pb, p, scr, rows, averaged_by_mat_[pb.mat] ? damage_increment_.data() + pb.i0 : nullptr);
  // In registers, not through s: the block's internal energy, and its fastest signal
  // (min_j h / s_j is h / max_j s_j exactly: a division is monotone, one is enough); partial
  // sums and maxima a vector of particles at a time (in a fixed order: the same bits each run).
  double internal = 0, fastest = 0, kinetic = 0;
  const double* __restrict m = p.m + pb.i0, * __restrict e = p.e + pb.i0;
  const double* __restrict v = p.v[pb.i0].data();
  const double* __restrict c = scr.c;
#pragma omp simd reduction(+ : internal, kinetic) reduction(max : fastest)
  for (int j = 0; j < pb.k; ++j) {
    internal += m[j] * e[j];
    double v2 = 0;
    for (int a = 0; a < D; ++a) v2 += v[D * j + a] * v[D * j + a];
    fastest = std::max(fastest, c[j] + std::sqrt(v2));
    kinetic += 0.5 * m[j] * v2;
  }
  s.internal += internal;
  if (motion) {
    s.kinetic += kinetic;
    for (int a = 0; a < D; ++a) {
      double q = 0;
#pragma omp simd reduction(+ : q)
      for (int j = 0; j < pb.k; ++j) q += m[j] * v[D * j + a];
      s.momentum[a] += q;
    }
  }
  s.dt_min = std::min(s.dt_min, blk.step_length() / fastest);  // the finest cell's step
  if (blk.fault_index >= 0 && s.fault < 0) {
    s.fault = pb.i0 + blk.fault_index;
    s.cause = blk.fault == PointFault::VolumeInverted
                  ? "its volume became non-positive (1 + tr(D) dt <= 0)"
                  : "its stress or energy is not finite";
  }
  pb.k = 0;
}

}  // namespace mpm
