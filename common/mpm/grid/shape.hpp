#pragma once
/// Trilinear (3D) and bilinear (2D) shape functions of the standard MPM cell.
/// Corner c of a cell has bit a of c set when it is the upper node along axis a.
#include <cmath>

#include "mpm/core/types.hpp"

namespace mpm {

template <int D>
inline constexpr int kCorners = 1 << D;

/// Weights N_c and gradients G_c (1/m) at a point whose position in its cell, as a fraction of
/// the cell size, is xi in [0,1)^D. inv_h = 1/h.
template <int D>
inline void shape_functions(const Vec<D>& xi, double inv_h, double N[kCorners<D>],
                            Vec<D> G[kCorners<D>]) {
  double w[D][2], dw[D][2];
  for (int a = 0; a < D; ++a) {
    w[a][0] = 1.0 - xi[a];
    w[a][1] = xi[a];
    dw[a][0] = -inv_h;
    dw[a][1] = inv_h;
  }
  for (int c = 0; c < kCorners<D>; ++c) {
    if constexpr (D == 3) {
      const int bx = c & 1, by = (c >> 1) & 1, bz = (c >> 2) & 1;
      N[c] = w[0][bx] * w[1][by] * w[2][bz];
      G[c][0] = dw[0][bx] * w[1][by] * w[2][bz];
      G[c][1] = w[0][bx] * dw[1][by] * w[2][bz];
      G[c][2] = w[0][bx] * w[1][by] * dw[2][bz];
    } else {
      const int bx = c & 1, by = (c >> 1) & 1;
      N[c] = w[0][bx] * w[1][by];
      G[c][0] = dw[0][bx] * w[1][by];
      G[c][1] = w[0][bx] * dw[1][by];
    }
  }
}

/// Weights only.
template <int D>
inline void shape_values(const Vec<D>& xi, double N[kCorners<D>]) {
  for (int c = 0; c < kCorners<D>; ++c) {
    double n = 1.0;
    for (int a = 0; a < D; ++a) n *= ((c >> a) & 1) ? xi[a] : 1.0 - xi[a];
    N[c] = n;
  }
}

}  // namespace mpm

namespace mpm {

/// Quadratic B-splines (Steffen, Kirby and Berzins 2008; the APIC paper's kernel): a particle
/// reaches the 3 nodes along each axis around its nearest node. xi in [0,1)^D is its position
/// from the midpoint between the stencil's first two nodes, in cells; stencil node s has
/// offsets k_a = (s / 3^a) % 3 and lies at (k - 1/2 - xi) h from the particle.
template <int D>
inline constexpr int kBsplineNodes = D == 2 ? 9 : 27;

/// The three weights along an axis and their derivatives (per cell).
inline void bspline_1d(double xi, double w[3], double dw[3]) {
  const double u = 1.0 - xi, t = xi - 0.5;
  w[0] = 0.5 * u * u, w[1] = 0.75 - t * t, w[2] = 0.5 * xi * xi;
  dw[0] = -u, dw[1] = -2.0 * t, dw[2] = xi;
}

/// Weights N_s and gradients G_s (1/m) of the stencil's nodes; inv_h = 1/h.
template <int D>
inline void bspline_functions(const Vec<D>& xi, double inv_h, double N[kBsplineNodes<D>],
                              Vec<D> G[kBsplineNodes<D>]) {
  double w[D][3], dw[D][3];
  for (int a = 0; a < D; ++a) {
    bspline_1d(xi[a], w[a], dw[a]);
    for (int k = 0; k < 3; ++k) dw[a][k] *= inv_h;
  }
  int s = 0;
  for (int kz = 0; kz < (D == 3 ? 3 : 1); ++kz)
    for (int ky = 0; ky < 3; ++ky)
      for (int kx = 0; kx < 3; ++kx, ++s) {
        if constexpr (D == 3) {
          N[s] = w[0][kx] * w[1][ky] * w[2][kz];
          G[s][0] = dw[0][kx] * w[1][ky] * w[2][kz];
          G[s][1] = w[0][kx] * dw[1][ky] * w[2][kz];
          G[s][2] = w[0][kx] * w[1][ky] * dw[2][kz];
        } else {
          N[s] = w[0][kx] * w[1][ky];
          G[s][0] = dw[0][kx] * w[1][ky];
          G[s][1] = w[0][kx] * dw[1][ky];
        }
      }
}

/// Weights only.
template <int D>
inline void bspline_values(const Vec<D>& xi, double N[kBsplineNodes<D>]) {
  double w[D][3], dw[D][3];
  for (int a = 0; a < D; ++a) bspline_1d(xi[a], w[a], dw[a]);
  int s = 0;
  for (int kz = 0; kz < (D == 3 ? 3 : 1); ++kz)
    for (int ky = 0; ky < 3; ++ky)
      for (int kx = 0; kx < 3; ++kx, ++s) {
        if constexpr (D == 3)
          N[s] = w[0][kx] * w[1][ky] * w[2][kz];
        else
          N[s] = w[0][kx] * w[1][ky];
      }
}

}  // namespace mpm
