#pragma once
/// Shape functions of the transition cells of a graded grid (004, section 3.1): a coarse cell
/// on a level interface carries, besides its 2^D corners, optional mid-edge (and in 3D
/// mid-face) nodes where the finer neighbour cells have corners. 5- to 8-node quadrilaterals in
/// 2D (004, eqs. 15-18) and 9- to 26-node hexahedra in 3D after McDill et al. (004, eqs. 19-22
/// and Table 1).
///
/// Derivation (the printed Table 1 has sign errors in its |.| terms, so nothing is copied from
/// it). In reference coordinates t in [-1, 1]^D a node sits at p in {-1, 0, 1}^D. Its raw
/// function is the product over the axes of
///     phi_{+1}(t) = (1 + t)/2,   phi_{-1}(t) = (1 - t)/2,   phi_0(t) = 1 - |t|,
/// i.e. N^S = (1/8)(1 + t_x p_x)(1 + t_y p_y)(1 + t_z p_z) for a corner (eq. 19),
/// (1/4)(1 - |t_a|)(1 + p_b t_b)(1 + p_c t_c) for a mid-edge node and
/// (1/2)(1 - |t_a|)(1 - |t_b|)(1 + p_c t_c) for a mid-face node (eq. 20). Each raw function is
/// multilinear in every sub-domain the planes t_a = 0 cut the cell into ("linear in each
/// sub-domain"). The hierarchical correction makes N_k vanish at every other present node:
/// going from the last node down to the first (faces, then edges, then corners),
///     N_k = raw_k - sum_{j present, j > k} raw_k(p_j) N_j,
/// where raw_k(p_j) is 1/2 for a face next to an edge or an edge next to a corner and 1/4 for
/// a face next to a corner (eqs. 17-18, 21-22). The sum over all N_k is 1 whatever nodes are
/// present, and a field linear in x is reproduced exactly.
///
/// Node numbering (1-based as in 004 Table 1; index k - 1 in code). 3D: corners 1 (+,+,+),
/// 2 (-,+,+), 3 (-,-,+), 4 (+,-,+), 5 (+,+,-), 6 (-,+,-), 7 (-,-,-), 8 (+,-,-); mid-edge nodes
/// 9 (0,+,+), 10 (-,0,+), 11 (0,-,+), 12 (+,0,+), 13 (0,+,-), 14 (-,0,-), 15 (0,-,-), 16 (+,0,-),
/// 17 (+,+,0), 18 (-,+,0), 19 (-,-,0), 20 (+,-,0); mid-face nodes 21 (+x), 22 (-x), 23 (+y),
/// 24 (-y), 25 (+z), 26 (-z). 2D: corners 1 (+,+), 2 (-,+), 3 (-,-), 4 (+,-); mid-edge nodes
/// 5 (+x, eq. 16), 6 (+y), 7 (-x), 8 (-y).
///
/// The grid hands the kernels the corners in its own bit order (corner c has bit a set when it
/// is the upper node along axis a) followed by the present optional nodes in increasing
/// number; `mask` bit j marks optional node kCorners + j + 1 (1-based) as present.
#include <array>
#include <cmath>
#include <cstdint>

#include "mpm/core/types.hpp"
#include "mpm/grid/shape.hpp"

namespace mpm {

/// Number of nodes of a full transition cell: 26 in 3D, 8 in 2D.
template <int D>
inline constexpr int kTransitionNodes = D == 3 ? 26 : 8;
/// Number of optional (mid-edge, mid-face) nodes: 18 in 3D, 4 in 2D.
template <int D>
inline constexpr int kOptionalNodes = kTransitionNodes<D> - kCorners<D>;

/// Topology of the transition cell: node positions p_k in {-1, 0, 1}^D (0-based k, the
/// numbering above), the grid's corner order, and the coefficients raw_k(p_j).
template <int D>
struct TransitionTopology {
  static constexpr int kN = kTransitionNodes<D>;
  std::array<std::array<int, D>, kN> p{};      ///< reference position of node k
  std::array<int, kCorners<D>> corner_bits{};  ///< grid corner index (bit order) of corner k
  std::array<std::array<double, kN>, kN> C{};  ///< C[k][j] = raw_k(p_j) for j > k, else 0
  constexpr TransitionTopology() {
    if constexpr (D == 3) {
      const int pos[26][3] = {
          {1, 1, 1},   {-1, 1, 1}, {-1, -1, 1}, {1, -1, 1}, {1, 1, -1},  {-1, 1, -1}, {-1, -1, -1},
          {1, -1, -1}, {0, 1, 1},  {-1, 0, 1},  {0, -1, 1}, {1, 0, 1},   {0, 1, -1},  {-1, 0, -1},
          {0, -1, -1}, {1, 0, -1}, {1, 1, 0},   {-1, 1, 0}, {-1, -1, 0}, {1, -1, 0},  {1, 0, 0},
          {-1, 0, 0},  {0, 1, 0},  {0, -1, 0},  {0, 0, 1},  {0, 0, -1}};
      for (int k = 0; k < kN; ++k)
        for (int a = 0; a < 3; ++a) p[k][a] = pos[k][a];
    } else {
      const int pos[8][2] = {{1, 1}, {-1, 1}, {-1, -1}, {1, -1}, {1, 0}, {0, 1}, {-1, 0}, {0, -1}};
      for (int k = 0; k < kN; ++k)
        for (int a = 0; a < 2; ++a) p[k][a] = pos[k][a];
    }
    for (int k = 0; k < kCorners<D>; ++k) {
      int c = 0;
      for (int a = 0; a < D; ++a)
        if (p[k][a] > 0) c |= 1 << a;
      corner_bits[k] = c;
    }
    for (int k = 0; k < kN; ++k)
      for (int j = k + 1; j < kN; ++j) {
        double v = 1;
        for (int a = 0; a < D; ++a) v *= phi(p[k][a], double(p[j][a]));
        C[k][j] = v;
      }
  }
  /// phi_q(t) for q in {-1, 0, 1}.
  static constexpr double phi(int q, double t) {
    if (q == 0) return 1.0 - (t < 0 ? -t : t);
    return 0.5 * (1.0 + q * t);
  }
};

template <int D>
inline constexpr TransitionTopology<D> kTransition{};

/// Weights N and gradients G (1/m) of a transition cell at xi in [0, 1]^D (position in the
/// cell as a fraction of its size h, inv_h = 1/h), for the optional nodes in `mask`. Fills the
/// corners in grid bit order, then the present optional nodes in increasing number; returns
/// the count. With mask 0 this is the standard cell (004, eqs. 15, 19). G may be nullptr.
template <int D>
inline int transition_shape(std::uint32_t mask, const Vec<D>& xi, double inv_h, double* N,
                            Vec<D>* G) {
  constexpr int kC = kCorners<D>, kN = kTransitionNodes<D>;
  const TransitionTopology<D>& T = kTransition<D>;
  // Per axis: phi_q(t) and dphi_q/dx for q = -1, 0, 1 (index q + 1), t = 2 xi - 1.
  double f[D][3], df[D][3];
  for (int a = 0; a < D; ++a) {
    const double t = 2.0 * xi[a] - 1.0, s = 2.0 * inv_h;  // dt/dx = 2/h
    f[a][0] = 0.5 * (1.0 - t);
    f[a][1] = 1.0 - std::abs(t);
    f[a][2] = 0.5 * (1.0 + t);
    df[a][0] = -0.5 * s;
    df[a][1] = (t >= 0 ? -1.0 : 1.0) * s;  // the kink of |t|: the t >= 0 side at t = 0
    df[a][2] = 0.5 * s;
  }
  // Present nodes, from the last down to the first (004, section 3.1: "from P_26 to P_1").
  int present[kN], np = 0;
  for (int j = kOptionalNodes<D> - 1; j >= 0; --j)
    if ((mask >> j) & 1u) present[np++] = kC + j;
  const int n_opt = np;
  for (int k = kC - 1; k >= 0; --k) present[np++] = k;
  double Nk[kN];
  Vec<D> Gk[kN];
  for (int q = 0; q < np; ++q) {
    const int k = present[q];
    // Raw function: the product of the axis factors, and its gradient.
    double v = 1.0;
    Vec<D> g = Vec<D>::Ones();
    for (int a = 0; a < D; ++a) {
      const int i = T.p[k][a] + 1;
      v *= f[a][i];
      for (int b = 0; b < D; ++b) g[b] *= (a == b ? df[a][i] : f[a][i]);
    }
    // Hierarchical correction by the present nodes numbered after k (004, eqs. 17-18, 21-22).
    for (int r = 0; r < q; ++r) {
      const int j = present[r];
      const double c = T.C[k][j];
      if (c != 0.0) {
        v -= c * Nk[j];
        g -= c * Gk[j];
      }
    }
    Nk[k] = v;
    Gk[k] = g;
  }
  // Output: corners in grid bit order, then the optional nodes in increasing number.
  for (int k = 0; k < kC; ++k) {
    N[T.corner_bits[k]] = Nk[k];
    if (G) G[T.corner_bits[k]] = Gk[k];
  }
  int out = kC;
  for (int q = n_opt - 1; q >= 0; --q) {
    const int k = present[q];
    N[out] = Nk[k];
    if (G) G[out] = Gk[k];
    ++out;
  }
  return out;
}

/// Smallest value any shape function of a transition cell takes. The functions are
/// multilinear in each of the 2^D sub-cells, so the minimum over the cell is the minimum over
/// the 3^D points t in {-1, 0, 1}^D, which this evaluates exactly.
template <int D>
inline double transition_min_value(std::uint32_t mask) {
  double lo = 1.0;
  int idx[D] = {};
  while (true) {
    Vec<D> xi = Vec<D>::Zero();
    for (int a = 0; a < D; ++a) xi[a] = 0.5 * idx[a];
    double N[kTransitionNodes<D>];
    const int n = transition_shape<D>(mask, xi, 1.0, N, nullptr);
    for (int k = 0; k < n; ++k) lo = std::min(lo, N[k]);
    int a = 0;
    while (a < D && ++idx[a] == 3) idx[a++] = 0;
    if (a == D) break;
  }
  return lo;
}

}  // namespace mpm
