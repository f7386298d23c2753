#pragma once
/// A background grid with nodes only where the material is: the cells that hold particles,
/// widened by one cell, and the corners of those cells. The dense window of UniformGrid spans
/// the particles' bounding box, which is right for a compact body and wasteful for a spreading
/// debris cloud (a thin shell and a spray inside a box that grows like the cube of its
/// extent). Here the node arrays grow with the occupied cells; the box itself costs one int32
/// a cell (the cell-to-key table).
///
/// Cells are numbered (keys) in the order of the dense window's keys: slab axis slowest, the
/// other axes in increasing order, so particles sort into the same order, bins, slab layers and
/// chunks as on the dense window. As long as both sort at the same steps, a run gives the same
/// results bit for bit (tested); a particle that enters a cell outside the active set asks
/// for a re-sort, as one leaving the dense window does.
#include <cstdint>
#include <vector>

#include "mpm/grid/grid.hpp"

namespace mpm {

template <int D>
class SparseGrid : public CellLattice<D>, public GridNodes<D> {
  using Base = CellLattice<D>;
  using Base::cells_;

 public:
  using Base::locate;
  static constexpr int kDim = D;
  static constexpr int kMaxNodes = kCorners<D>;
  static constexpr bool kFixedNodes = true;
  static constexpr bool kGraded = false;

  SparseGrid(const Lattice& lattice, const BoundarySpec& boundary);

  /// Activates the cells of the n particles widened by `margin` cells (clamped to the domain),
  /// numbers the active cells and their corner nodes, and sizes the node arrays.
  void fit(const Vec<D>* x, std::size_t n, int margin = 1);

  // Geometry (locate, in_domain, shape, values, cell sizes: CellLattice) -------------------
  /// Cell key and local coordinates of a point known to lie in an active cell.
  void locate(const Vec<D>& x, std::int64_t& key, Vec<D>& xi) const {
    IVec<D> cell;
    locate(x, cell, xi);
    key = cell_key_[box_index(cell)];
  }
  Where where(const Vec<D>& x, std::int64_t& key, Vec<D>& xi) const {
    IVec<D> cell;
    locate(x, cell, xi);
    if (!this->in_domain(cell)) return Where::OutsideDomain;
    if (!in_box(cell)) return Where::OutsideWindow;
    const std::int32_t k = cell_key_[box_index(cell)];
    if (k < 0) return Where::OutsideWindow;
    key = k;
    return Where::Window;
  }
  int cell_nodes(std::int64_t key, std::int64_t* nodes) const {
    const std::int32_t* c = &cell_nodes_[std::size_t(key) * kMaxNodes];
    for (int i = 0; i < kMaxNodes; ++i) nodes[i] = c[i];
    return kMaxNodes;
  }
  std::size_t key_count() const { return cell_layer_.size(); }
  int layer(std::int64_t key) const { return cell_layer_[std::size_t(key)]; }
  int layers() const { return hi_[slab_] - lo_[slab_] + 1; }
  int slab_axis() const { return slab_; }
  /// Cells in the box the active cells lie in (the cell-to-key table's length).
  std::size_t box_cells() const { return cell_key_.size(); }
  /// The box of global nodes [lo, hi] the active nodes lie in.
  void node_box(IVec<D>& lo, IVec<D>& hi) const { lo = lo_, hi = hi_ + IVec<D>::Ones(); }
  /// Index of the active node at global node k (a corner of an active cell), -1 when none.
  std::int64_t node_at(const IVec<D>& k) const {
    for (int c = 0; c < kMaxNodes; ++c) {
      IVec<D> cell = k;
      for (int a = 0; a < D; ++a) cell[a] -= (c >> a) & 1;
      if (!in_box(cell)) continue;
      const std::int32_t key = cell_key_[box_index(cell)];
      if (key >= 0) return cell_nodes_[std::size_t(key) * kMaxNodes + std::size_t(c)];
    }
    return -1;
  }

  // Node data and constrained nodes (the active ones): GridNodes.

 private:
  bool in_box(const IVec<D>& cell) const {
    for (int a = 0; a < D; ++a)
      if (cell[a] < lo_[a] || cell[a] > hi_[a]) return false;
    return true;
  }
  /// Index of a global cell in the box (slab axis slowest, the others in increasing order).
  std::size_t box_index(const IVec<D>& cell) const {
    std::size_t k = 0;
    for (int a = 0; a < D; ++a) k += std::size_t(cell[a] - lo_[a]) * stride_[a];
    return k;
  }

  IVec<D> lo_, hi_;                      ///< the box of active cells (inclusive)
  std::array<std::size_t, D> stride_{};  ///< of the box's cells
  int slab_ = D - 1;
  std::vector<std::int32_t> cell_key_;    ///< box cell -> key, -1 when inactive
  std::vector<std::int32_t> cell_nodes_;  ///< key -> its kMaxNodes node indices
  std::vector<std::int32_t> cell_layer_;  ///< key -> slab layer
};

}  // namespace mpm
