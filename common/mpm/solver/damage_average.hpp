#pragma once
/// Nonlocal damage (docs/scene.md, HJC concrete, `damage_length`): the damage increments one
/// step's constitutive update found in each particle of a material are averaged over a length
/// before they are added, so that the zone a crack or a crushed tunnel damages is set by that
/// length and not by the cells it happens to fall in.
///
/// The average goes through a lattice of spacing l anchored at the origin (independent of the
/// grid's levels, so the same on every level of a graded grid and on every rank): each particle
/// scatters its mass and its mass times its increment to the 2^D nodes of its lattice cell with
/// multilinear weights w, each node holds the mass-weighted mean d_I = Q_I / M_I, and each
/// particle takes back sum_I w_I d_I. So a uniform increment stays uniform, the sum of m_p dD_p
/// over the material is kept exactly (sum_I d_I M_I = sum_I Q_I), and a particle's increment
/// spreads over at most 2 l each way (a tent of half-width l, scattered and gathered). Near a
/// free surface or a symmetry plane the mean is over the material there (the ratio has no
/// missing-mirror bias). Only the lattice's bounding box of the particles that damaged this
/// step is stored (dense), so the cost is three passes over the particles (the box, the
/// scatter, the gather) plus the damaging zone's nodes. The scatter runs serially in particle order
/// (the same bits for any thread count); under mpirun the box is agreed between the ranks and the
/// lattice summed across them.
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "mpm/core/comm.hpp"
#include "mpm/core/types.hpp"

namespace mpm {

/// The particles one average reads and writes (arrays of n, in the particle columns' order).
template <int D>
struct DamageAverageInput {
  std::size_t n = 0;
  const Vec<D>* x = nullptr;               ///< positions, m
  const double* m = nullptr;               ///< masses, kg
  const std::uint8_t* material = nullptr;  ///< material index
  int mat = 0;                             ///< the material averaged
  double length = 0;                       ///< lattice spacing l, m
  const double* increment = nullptr;       ///< this step's local damage increments (of mat's)
  double* damage = nullptr;                ///< damage, in/out: D += averaged increment, D <= 1
};

/// Averages the increments of material `in.mat` and adds them to its damage (capped at 1).
/// `comm` is null or the ranks of an mpirun (every rank calls it). Returns the lattice nodes
/// used (0 when no particle damaged this step).
template <int D>
std::size_t average_damage(const DamageAverageInput<D>& in, const Comm* comm,
                           std::vector<double>& Q, std::vector<double>& M) {
  const double inv_l = 1.0 / in.length;
  // The lattice cell of each damaging particle: the box of their nodes.
  std::array<double, D> lo, hi;
  lo.fill(std::numeric_limits<double>::infinity());
  hi.fill(-std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < in.n; ++i) {
    if (in.material[i] != in.mat || !(in.increment[i] > 0)) continue;
    for (int a = 0; a < D; ++a) {
      const double c = std::floor(in.x[i][a] * inv_l);
      lo[a] = std::min(lo[a], c);
      hi[a] = std::max(hi[a], c + 1.0);
    }
  }
  if (comm && comm->parallel())
    for (int a = 0; a < D; ++a) lo[a] = comm->min(lo[a]), hi[a] = comm->max(hi[a]);
  if (!(lo[0] <= hi[0])) return 0;  // nothing damaged this step, on any rank
  std::array<std::int64_t, D> base, size;
  std::size_t nodes = 1;
  for (int a = 0; a < D; ++a) {
    base[a] = std::int64_t(lo[a]);
    size[a] = std::int64_t(hi[a]) - base[a] + 1;
    nodes *= std::size_t(size[a]);
  }
  Q.assign(nodes, 0.0);
  M.assign(nodes, 0.0);
  // A particle's cell (c), its local coordinates (f in [0, 1)), and whether any of its nodes
  // lies in the box.
  auto locate = [&](std::size_t i, std::array<std::int64_t, D>& c, std::array<double, D>& f) {
    bool touches = true;
    for (int a = 0; a < D; ++a) {
      const double s = in.x[i][a] * inv_l, fl = std::floor(s);
      c[a] = std::int64_t(fl) - base[a];
      f[a] = s - fl;
      touches = touches && c[a] >= -1 && c[a] < size[a];
    }
    return touches;
  };
  // Visits the 2^D corners of cell c inside the box: fn(node index, weight).
  auto corners = [&](const std::array<std::int64_t, D>& c, const std::array<double, D>& f,
                     auto&& fn) {
    for (int k = 0; k < (1 << D); ++k) {
      double w = 1.0;
      std::size_t node = 0;
      bool inside = true;
      for (int a = D - 1; a >= 0; --a) {
        const int up = (k >> a) & 1;
        const std::int64_t j = c[a] + up;
        inside = inside && j >= 0 && j < size[a];
        w *= up ? f[a] : 1.0 - f[a];
        node = node * std::size_t(size[a]) + std::size_t(std::max<std::int64_t>(j, 0));
      }
      if (inside && w > 0) fn(node, w);
    }
  };
  for (std::size_t i = 0; i < in.n; ++i) {  // scatter, serially: the same sums every run
    if (in.material[i] != in.mat) continue;
    std::array<std::int64_t, D> c;
    std::array<double, D> f;
    if (!locate(i, c, f)) continue;
    const double m = in.m[i], q = m * in.increment[i];
    corners(c, f, [&](std::size_t node, double w) {
      M[node] += w * m;
      Q[node] += w * q;
    });
  }
  if (comm && comm->parallel()) {
    comm->sum(Q.data(), int(nodes));
    comm->sum(M.data(), int(nodes));
  }
  for (std::size_t k = 0; k < nodes; ++k) Q[k] = M[k] > 0 ? Q[k] / M[k] : 0.0;  // d_I
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < in.n; ++i) {  // gather
    if (in.material[i] != in.mat) continue;
    std::array<std::int64_t, D> c;
    std::array<double, D> f;
    if (!locate(i, c, f)) continue;
    double d = 0;
    corners(c, f, [&](std::size_t node, double w) { d += w * Q[node]; });
    if (d > 0) in.damage[i] = std::min(in.damage[i] + d, 1.0);
  }
  return nodes;
}

}  // namespace mpm
