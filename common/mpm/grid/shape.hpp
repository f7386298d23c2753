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
