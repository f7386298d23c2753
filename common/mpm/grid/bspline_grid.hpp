#pragma once
/// The uniform grid with quadratic B-spline shape functions (grid.shape = "bspline"). A
/// particle reaches the 3^D nodes around its nearest node, so the grid's "cells" here are the
/// dual cells between node midpoints: a particle's key is the window index of its stencil's
/// first node. The lattice is the domain's widened by one cell on every side, whose nodes are
/// the ghost nodes that particles within half a cell of a face reach; beyond a constrained face
/// they mirror the nodes inside (grid.hpp, GridNodes::GhostNode).
///
/// Why: a linear node at a cell's far corner gets a sliver of a particle's mass but the full
/// gradient of its force, so its velocity is noise that USL-type updates feed back (MUSL's
/// remap exists for that). A B-spline node's force falls with its weight (dN^2 / N stays
/// bounded), and the gradient is continuous as a particle crosses a cell: APIC's affine
/// transfer needs both (Jiang et al. 2015, section 5).
#include <cmath>
#include <cstdint>

#include "mpm/grid/grid.hpp"

namespace mpm {

/// The lattice widened by one cell on every side (the ghost nodes).
inline Lattice with_ghost_cells(Lattice lattice) {
  for (int a = 0; a < lattice.dim; ++a) {
    lattice.origin[a] -= lattice.h;
    lattice.cells[a] += 2;
  }
  return lattice;
}

template <int D>
class BsplineGrid : public UniformGrid<D> {
  using Base = UniformGrid<D>;
  using Base::cells_;
  using Base::hi_, Base::lo_, Base::stride_;

 public:
  static constexpr int kDim = D;
  static constexpr int kMaxNodes = kBsplineNodes<D>;
  static constexpr bool kFixedNodes = true;
  static constexpr bool kGraded = false;
  /// Node layers a particle's stencil spans along the slab axis (binning: chunks of at least
  /// kStencilLayers - 1 layers keep two chunks of one colour apart).
  static constexpr int kStencilLayers = 3;
  /// APIC's inertia-like tensor D_p = sum N (x_i - x_p)(x_i - x_p)^T = h^2 / 4 I.
  static constexpr double kInertia = 0.25;

  BsplineGrid(const Lattice& lattice, const BoundarySpec& boundary)
      : Base(with_ghost_cells(lattice), boundary, 1), domain_(lattice) {}

  /// The scene's lattice (without the ghost cells).
  const Lattice& lattice() const { return domain_; }

  /// A point's stencil (its first node, as a window key) and its place xi in [0,1)^D from
  /// the midpoint between the stencil's first two nodes.
  void locate(const Vec<D>& x, std::int64_t& key, Vec<D>& xi) const {
    IVec<D> base;
    dual(x, base, xi);
    key = this->key(base);
  }
  Where where(const Vec<D>& x, std::int64_t& key, Vec<D>& xi) const {
    const Vec<D> r = (x - this->origin()) * this->inv_h();
    for (int a = 0; a < D; ++a) {
      const double c = std::floor(r[a]);  // cell of the widened lattice: the domain is 1..n-2
      if (!(c >= 1 && c <= cells_[a] - 2)) return Where::OutsideDomain;
    }
    IVec<D> base;
    dual(x, base, xi);
    for (int a = 0; a < D; ++a)
      if (base[a] < lo_[a] || base[a] > hi_[a] - 1) return Where::OutsideWindow;
    key = this->key(base);
    return Where::Window;
  }
  /// The stencil's nodes (x fastest); returns their number.
  int cell_nodes(std::int64_t key, std::int64_t* nodes) const {
    int s = 0;
    for (int kz = 0; kz < (D == 3 ? 3 : 1); ++kz)
      for (int ky = 0; ky < 3; ++ky)
        for (int kx = 0; kx < 3; ++kx, ++s) {
          std::int64_t n = key + kx * stride_[0] + ky * stride_[1];
          if constexpr (D == 3) n += kz * stride_[2];
          nodes[s] = n;
        }
    return kMaxNodes;
  }
  void shape(std::int64_t, const Vec<D>& xi, double* N, Vec<D>* G) const {
    bspline_functions<D>(xi, this->inv_h(), N, G);
  }
  void values(std::int64_t, const Vec<D>& xi, double* N) const { bspline_values<D>(xi, N); }
  /// x_i - x_p of the stencil's nodes, in cells.
  void offsets(std::int64_t, const Vec<D>& xi, Vec<D>* d) const {
    int s = 0;
    for (int kz = 0; kz < (D == 3 ? 3 : 1); ++kz)
      for (int ky = 0; ky < 3; ++ky)
        for (int kx = 0; kx < 3; ++kx, ++s) {
          d[s][0] = kx - 0.5 - xi[0];
          d[s][1] = ky - 0.5 - xi[1];
          if constexpr (D == 3) d[s][2] = kz - 0.5 - xi[2];
        }
  }
  /// APIC's C_p = sum_i v_i W_i^T = B_p D_p^-1, W_i = N_i (x_i - x_p) / (h^2 / 4).
  void affine_weights(std::int64_t key, const Vec<D>& xi, const double* N, const Vec<D>*,
                      Vec<D>* W) const {
    offsets(key, xi, W);
    const double s = this->inv_h() / kInertia;  // (x_i - x_p) = h d: N h d / (h^2 / 4)
    for (int c = 0; c < kMaxNodes; ++c) W[c] *= s * N[c];
  }

 private:
  /// The stencil's first node (global, widened lattice) and xi.
  void dual(const Vec<D>& x, IVec<D>& base, Vec<D>& xi) const {
    const Vec<D> r = (x - this->origin()) * this->inv_h();
    for (int a = 0; a < D; ++a) {
      const double f = std::floor(r[a] - 0.5);
      base[a] = int(f);
      xi[a] = r[a] - 0.5 - f;
    }
  }

  Lattice domain_;
};

static_assert(Grid<BsplineGrid<2>> && Grid<BsplineGrid<3>>);

}  // namespace mpm
