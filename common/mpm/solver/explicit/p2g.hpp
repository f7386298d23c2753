#pragma once
// Particle to grid (000, eqs. 1-5): lumped mass, momentum, internal force, body forces and
// loads. A particle in its bin's cell adds into registers flushed once per cell.
#include "mpm/solver/explicit/explicit_solver.hpp"

namespace mpm {

template <Grid GridT>
template <int F>
void ExplicitSolver<GridT>::p2g() {
  ScopedTimer timer(timers_, timers_.id(F == kForce    ? "p2g_force"
                                        : (F & kForce) ? "p2g"
                                                       : "p2g_mass_momentum"));
  if constexpr (F & kMass) {
    grid_.clear(scheme_ == Scheme::MUSL, has_rigid_);
    if (has_rigid_) {
      mark_rigid_nodes();
      if constexpr (Core::kRanks)
        if (ranks_) ranks_->max_shared(grid_.rigid);  // bodies on other ranks touch them too
    }
    if (contact_.active()) contact_.clear(grid_.nodes(), scheme_ == Scheme::MUSL);
  }
  if (contact_.active())
    scatter_to_grid<F, true>();
  else
    scatter_to_grid<F, false>();
  sum_shared(F);
  fold_ghosts(F);
}

/// Under mpirun: the nodes this rank's window shares with its neighbours' summed across them
/// (RankSlabs::sum_shared), so that every rank holds the whole grid its particles see.
template <Grid GridT>
void ExplicitSolver<GridT>::sum_shared([[maybe_unused]] int fields) {
  if constexpr (Core::kRanks)
    if (ranks_) {
      ScopedTimer timer(timers_, timers_.id("ranks_nodes"));
      ranks_->sum_shared(grid_, fields);
    }
}

/// B-spline grids: the ghost nodes' mass, momentum, force or remapped momentum (the `fields`
/// just scattered) folded into their mirrors, reflected (GridNodes::GhostNode).
template <Grid GridT>
void ExplicitSolver<GridT>::fold_ghosts([[maybe_unused]] int fields) {
  if constexpr (kGhosts)
    for (const auto& g : grid_.ghost_nodes()) {
      if (g.mirror < 0 || grid_.m[g.node] == 0) continue;
      if (fields & kMass) grid_.m[g.mirror] += grid_.m[g.node];
      if (fields & kMomentum) grid_.v[g.mirror] += grid_.reflect(g, grid_.v[g.node]);
      if (fields & kForce) grid_.a[g.mirror] += grid_.reflect(g, grid_.a[g.node]);
      if (fields & kRemap) grid_.v_remap[g.mirror] += grid_.reflect(g, grid_.v_remap[g.node]);
    }
}

/// The scatter of p2g; with contact (C), the particles of the bodies in contact add into
/// their bodies' fields instead of the common one.
template <Grid GridT>
template <int F, bool C>
void ExplicitSolver<GridT>::scatter_to_grid() {
  constexpr bool kM = F & kMass, kP = F & kMomentum, kF = F & kForce;
  const ParticleView<D> p = view<D>(particles_);
  material_ = p.material;
  const auto& bins = binning_.bins();
  const Vec<D> b = gravity_;
  const bool axi = axisymmetric_;

  // Contribution of particle i (cell `key`, local coordinates xi) through add(c, dm, dp, df).
  auto contribute = [&](std::uint32_t i, std::int64_t key, const Vec<D>& xi, int nn, auto&& add) {
    double N[NMAX];
    Vec<D> G[NMAX];
    if constexpr (kF)
      grid_.shape(key, xi, N, G);
    else
      grid_.values(key, xi, N);
    const double m_p = p.m[i];
    const Vec<D> mv_p = m_p * p.v[i];
    Mat<D> Vsigma = Mat<D>::Zero();  // V_p sigma_p, in-plane part
    double Vs_hoop_r = 0;            // axisymmetric: V_p sigma_thetatheta / r_p
    Vec<D> fb = m_p * b;             // body force and load
    if constexpr (kF) {
      const double V = m_p / p.rho[i];
      Vsigma = V * to_matrix(p.sigma[i]).template topLeftCorner<D, D>();
      if (axi) Vs_hoop_r = V * p.sigma[i][2] / p.x[i][0];
      if (p.f_ext) fb += p.f_ext[i];
      if (p.f_rebar) fb += p.f_rebar[i];  // the rebar elements' force on a node (004, eq. 13)
    }
    // APIC: the momentum of the particle's affine field, m_p C_p (x_i - x_p), x_i - x_p = h d_i.
    Vec<D> d[NMAX];
    Mat<D> mhC;
    const bool affine = kAffine && kP && p.C;
    if constexpr (kAffine)
      if (affine) grid_.offsets(key, xi, d), mhC = (m_p * grid_.cell_size(key)) * p.C[i];
    for (int c = 0; c < nn; ++c) {
      Vec<D> df = Vec<D>::Zero();
      if constexpr (kF) {
        df = N[c] * fb - Vsigma * G[c];      // (000, eqs. 4-5)
        if (axi) df[0] -= Vs_hoop_r * N[c];  // hoop stress (Sulsky & Schreyer 1996)
      }
      if (affine)
        add(c, m_p * N[c], N[c] * (mv_p + mhC * d[c]), df);
      else
        add(c, m_p * N[c], N[c] * mv_p, df);
    }
  };
  // Writes into a target at the nodes of a cell.
  auto to_target = [&](const Target& t, const std::int64_t* nodes) {
    return [&t, nodes](int c, double dm, const Vec<D>& dp, const Vec<D>& df) {
      const std::int64_t n = nodes[c] - t.offset;
      if constexpr (kM) t.m[n] += dm;
      if constexpr (kP) t.v[n] += dp;
      if constexpr (kF) t.a[n] += df;
    };
  };
  auto particle_body = [&] [[gnu::flatten]] (std::uint32_t i, const Target& t, bool, int) {
    if (rigid(i)) return;
    std::int64_t key, nodes[NMAX];
    Vec<D> xi;
    grid_.locate(p.x[i], key, xi);
    const int nn = grid_.cell_nodes(key, nodes);
    if constexpr (C)
      if (const int f = contact_.field_of(p.body[i]))
        return add_to_field<F>(p, i, f, key, xi, nodes, nn);
    contribute(i, key, xi, nn, to_target(t, nodes));
  };
  auto bin_body = [&] [[gnu::flatten]] (int, std::uint32_t bi, const Target& t,
                                        std::vector<std::uint32_t>* strays) {
    const Bin& bin = bins[bi];
    const int layer = grid_.layer(bin.key);
    std::int64_t nodes[NMAX];
    const int nn = grid_.cell_nodes(bin.key, nodes);
    double m_c[NMAX] = {};
    Vec<D> p_c[NMAX], f_c[NMAX];
    for (int c = 0; c < nn; ++c) p_c[c].setZero(), f_c[c].setZero();
    auto to_cell = [&](int c, double dm, const Vec<D>& dp, const Vec<D>& df) {
      if constexpr (kM) m_c[c] += dm;
      if constexpr (kP) p_c[c] += dp;
      if constexpr (kF) f_c[c] += df;
    };
    // Uniform and sparse 3D cells: the particles in the bin's cell add into sums by corner and
    // by edge (trilinear_add), shared out to the corners at the end (trilinear_corners).
    const bool trilinear = kTrilinear && !C && !axi && !(kAffine && kP && p.C);
    TrilinearSums ts{};
    for (std::uint32_t i = bin.begin; i < bin.end; ++i) {
      if (rigid(i)) continue;
      std::int64_t key;
      Vec<D> xi;
      locate_in_bin(bin, p.x[i], key, xi);
      if (trilinear && key == bin.key) {
        trilinear_add<F>(p, i, xi, ts);
        continue;
      }
      if constexpr (C)
        if (const int f = contact_.field_of(p.body[i])) {
          add_in_bin<F>(p, i, f, bin.key, key, xi, nodes, nn, layer, strays);
          continue;
        }
      if (key == bin.key) {
        contribute(i, key, xi, nn, to_cell);
      } else if (!strays || grid_.layer(key) == layer) {
        std::int64_t other[NMAX];
        const int nk = grid_.cell_nodes(key, other);
        contribute(i, key, xi, nk, to_target(t, other));
      } else {
        strays->push_back(i);
      }
    }
    if (trilinear) trilinear_corners<F>(ts, m_c, p_c, f_c);
    for (int c = 0; c < nn; ++c) {
      const std::int64_t n = nodes[c] - t.offset;
      if constexpr (kM) t.m[n] += m_c[c];
      if constexpr (kP) t.v[n] += p_c[c];
      if constexpr (kF) t.a[n] += f_c[c];
    }
  };
  scatter(F, bin_body, particle_body);  // scatter.hpp
}

/// Uniform and sparse 3D cells: particle i's mass, momentum and force into the bin's sums.
/// With trilinear weights N_c = w_x w_y w_z, the force -V sigma G_c on corner c is, along
/// axis a, -/+ (1/h) V sigma(:, a) times the product of the other two weights, which is the
/// same for the two corners of an edge along a: the particle adds 3 x 3 x 4 products into
/// the edges' sums (trilinear_corners shares them out) where the corners took 8 x 9.
template <Grid GridT>
template <int F>
[[gnu::always_inline]] inline void ExplicitSolver<GridT>::trilinear_add(const ParticleView<D>& p,
                                                                        std::uint32_t i,
                                                                        const Vec<D>& xi,
                                                                        TrilinearSums& ts) const {
  if constexpr (kTrilinear) {
    // In vectors over the corners and edges (lanes.hpp).
    using lanes::spread4;
    const double x1 = xi[0], y1 = xi[1], z1 = xi[2], x0 = 1.0 - x1, y0 = 1.0 - y1, z0 = 1.0 - z1;
    const lanes::V8 N = lanes::corner_weights(x1, y1, z1);
    const double m_p = p.m[i];
    if constexpr (F & kMass) ts.m += m_p * N;
    if constexpr (F & kMomentum)
      for (int r = 0; r < 3; ++r) ts.p[r] += (m_p * p.v[i][r]) * N;
    if constexpr (F & kForce) {
      const double V = m_p / p.rho[i];
      const Sym& sg = p.sigma[i];
      const double Vs[3][3] = {{V * sg[0], V * sg[5], V * sg[4]},
                               {V * sg[5], V * sg[1], V * sg[3]},
                               {V * sg[4], V * sg[3], V * sg[2]}};
      // The other two axes' weights on the edges along each axis a: along x, e = by + 2 bz;
      // along y, e = bx + 2 bz; along z, e = bx + 2 by.
      const lanes::V4 W[3] = {spread4(y0, y1, 1) * spread4(z0, z1, 2),
                              spread4(x0, x1, 1) * spread4(z0, z1, 2),
                              spread4(x0, x1, 1) * spread4(y0, y1, 2)};
      for (int a = 0; a < 3; ++a)
        for (int r = 0; r < 3; ++r) ts.s[a][r] += Vs[r][a] * W[a];
      if (loads_ || p.f_rebar) {  // body force, loads, rebar (without, ts.b stays zero)
        Vec<D> fb = m_p * gravity_;
        if (p.f_ext) fb += p.f_ext[i];
        if (p.f_rebar) fb += p.f_rebar[i];
        for (int r = 0; r < 3; ++r) ts.b[r] += fb[r] * N;
      }
    }
  }
}

/// The bin's trilinear sums shared out to its corners: mass and momentum as summed, the force
/// N fb - (1/h) sum_a sign_a(c) s_a(edge of c along a) (sign -1 at the lower corner).
template <Grid GridT>
template <int F>
void ExplicitSolver<GridT>::trilinear_corners(const TrilinearSums& ts, double* m_c, Vec<D>* p_c,
                                              Vec<D>* f_c) const {
  if constexpr (kTrilinear) {
    const double ih = grid_.inv_h();
    for (int c = 0; c < 8; ++c) {
      const int bx = c & 1, by = (c >> 1) & 1, bz = c >> 2;
      if constexpr (F & kMass) m_c[c] += ts.m[c];
      for (int r = 0; r < 3; ++r) {
        if constexpr (F & kMomentum) p_c[c][r] += ts.p[r][c];
        if constexpr (F & kForce) {
          const double gx = bx ? ts.s[0][r][by + 2 * bz] : -ts.s[0][r][by + 2 * bz];
          const double gy = by ? ts.s[1][r][bx + 2 * bz] : -ts.s[1][r][bx + 2 * bz];
          const double gz = bz ? ts.s[2][r][bx + 2 * by] : -ts.s[2][r][bx + 2 * by];
          f_c[c][r] += ts.b[r][c] - ih * (gx + gy + gz);
        }
      }
    }
  }
}

/// A particle of a body in contact, in a bin's scatter: into its body's field at its cell's
/// nodes, or a stray when that cell is in another layer (scatter.hpp).
template <Grid GridT>
template <int F>
void ExplicitSolver<GridT>::add_in_bin(const ParticleView<D>& p, std::uint32_t i, int f,
                                       std::int64_t bin_key, std::int64_t key, const Vec<D>& xi,
                                       const std::int64_t* nodes, int nn, int layer,
                                       std::vector<std::uint32_t>* strays) {
  if (key != bin_key && strays && grid_.layer(key) != layer) {
    strays->push_back(i);
    return;
  }
  std::int64_t other[NMAX];
  const bool home = key == bin_key;
  const int nk = home ? nn : grid_.cell_nodes(key, other);
  add_to_field<F>(p, i, f, key, xi, home ? nodes : other, nk);
}

template <Grid GridT>
template <int F>
void ExplicitSolver<GridT>::add_to_field(const ParticleView<D>& p, std::uint32_t i, int f,
                                         std::int64_t key, const Vec<D>& xi, const std::int64_t* nd,
                                         int nk) {
  constexpr bool kM = F & kMass, kP = F & kMomentum, kF = F & kForce;
  auto& fd = contact_.field(f);
  double N[NMAX];
  Vec<D> G[NMAX];
  grid_.shape(key, xi, N, G);
  const double m_p = p.m[i];
  const Vec<D> mv_p = m_p * p.v[i];
  const bool volume = kM && !fd.V.empty();
  const double V_p = volume ? m_p / p.rho[i] : 0.0;
  // The section's mass in axisymmetry (contact.hpp, "Symmetry"): the normal of the r-z section.
  const double m_g = kM && axisymmetric_ ? m_p / p.x[i][0] : m_p;
  for (int c = 0; c < nk; ++c) {
    const std::int64_t n = nd[c];
    if constexpr (kM) {
      fd.m[n] += m_p * N[c];
      fd.g[n] += m_g * G[c];              // the body's mass gradient: the contact normal
      fd.x[n] += (m_p * N[c]) * p.x[i];   // its centre: the gap
      if (volume) fd.V[n] += V_p * N[c];  // its share of the node: where its surface is
    }
    if constexpr (kP) fd.v[n] += N[c] * mv_p;
  }
  if constexpr (kF) {
    const double V = m_p / p.rho[i];
    const Mat<D> Vsigma = V * to_matrix(p.sigma[i]).template topLeftCorner<D, D>();
    const double Vs_hoop_r = axisymmetric_ ? V * p.sigma[i][2] / p.x[i][0] : 0.0;
    Vec<D> fb = m_p * gravity_;
    if (p.f_ext) fb += p.f_ext[i];
    if (p.f_rebar) fb += p.f_rebar[i];
    for (int c = 0; c < nk; ++c) {
      Vec<D> df = N[c] * fb - Vsigma * G[c];         // (000, eqs. 4-5)
      if (axisymmetric_) df[0] -= Vs_hoop_r * N[c];  // hoop stress
      fd.a[nd[c]] += df;
    }
  }
}

// Rigid particles mark the nodes they touch with their body, serially:
// they are few, and a node touched by two rigid bodies then takes the later one's mark.
template <Grid GridT>
void ExplicitSolver<GridT>::mark_rigid_nodes() {
  const ParticleView<D> p = view<D>(particles_);
  for (std::size_t i = 0; i < p.n; ++i) {
    if (p.material[i] != kRigidMaterial) continue;
    std::int64_t key, nodes[NMAX];
    Vec<D> xi;
    double N[NMAX];
    grid_.locate(p.x[i], key, xi);
    grid_.values(key, xi, N);
    const int nn = grid_.cell_nodes(key, nodes);
    for (int c = 0; c < nn; ++c)
      if (N[c] > 0) grid_.rigid[nodes[c]] = rigid_mark_[p.body[i]];
  }
}

}  // namespace mpm
