#include "mpm/grid/grid.hpp"

#include <omp.h>

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace mpm {

template <int D>
CellLattice<D>::CellLattice(const Lattice& lattice) : h_(lattice.h), inv_h_(1.0 / lattice.h) {
  if (lattice.dim != D) throw std::logic_error("lattice dimension does not match the solver");
  for (int a = 0; a < D; ++a) {
    origin_[a] = lattice.origin[a];
    cells_[a] = lattice.cells[a];
  }
}

template <int D>
int CellLattice<D>::particle_box(const Vec<D>* x, std::size_t n, int margin, IVec<D>& lo,
                                 IVec<D>& hi) const {
  IVec<D> plo, phi;  // the particles' cells
  cell_bounds<D>(x, n, origin_, inv_h_, cells_, plo, phi);
  for (int a = 0; a < D; ++a) {
    lo[a] = std::max(0, plo[a] - margin);
    hi[a] = std::min(cells_[a] - 1, phi[a] + margin);
  }
  int slab = D - 1;
  for (int a = D - 2; a >= 0; --a)
    if (hi[a] - lo[a] > hi[slab] - lo[slab]) slab = a;
  return slab;
}

template <int D>
UniformGrid<D>::UniformGrid(const Lattice& lattice, const BoundarySpec& boundary, int ghost)
    : Base(lattice), GridNodes<D>(boundary), lattice_(lattice), ghost_(ghost) {
  for (int a = 0; a < D; ++a) {
    lo_[a] = 0;
    hi_[a] = cells_[a] - 1;
  }
}

template <int D>
void UniformGrid<D>::fit(const Vec<D>* x, std::size_t n, int margin) {
  // Slab axis: the longest extent (ties go to the highest axis). It is the slowest index of
  // the node layout and of the particle order, so a slab of layers is a contiguous range.
  slab_ = this->particle_box(x, n, margin, lo_, hi_);
  for (int a = 0; a < D; ++a) nodes_[a] = hi_[a] - lo_[a] + 2;
  std::int64_t s = 1;
  for (int a = 0; a < D; ++a)
    if (a != slab_) stride_[a] = s, s *= nodes_[a];
  stride_[slab_] = s;
  s *= nodes_[slab_];
  if (s > std::int64_t(std::numeric_limits<std::uint32_t>::max()))
    throw std::runtime_error("grid window of " + std::to_string(s) +
                             " nodes exceeds 2^32; use larger cells");
  for (int c = 0; c < kCorners<D>; ++c) {
    std::int64_t off = 0;
    for (int a = 0; a < D; ++a)
      if ((c >> a) & 1) off += stride_[a];
    corner_[c] = off;
  }
  this->resize_nodes(std::size_t(s));  // the arrays now mean other nodes
  // Nodes on constrained domain faces that the window reaches.
  this->collect_face_nodes(
      cells_, lo_, nodes_,
      [&](const IVec<D>& k) {
        std::int64_t idx = 0;
        for (int b = 0; b < D; ++b) idx += std::int64_t(k[b]) * stride_[b];
        return idx;
      },
      ghost_);
}

template <int D>
IVec<D> UniformGrid<D>::global_node(std::int64_t index) const {
  IVec<D> k;
  for (int a = 0; a < D; ++a) k[a] = int((index / stride_[a]) % nodes_[a]) + lo_[a];
  return k;
}

template class CellLattice<2>;
template class CellLattice<3>;
template class UniformGrid<2>;
template class UniformGrid<3>;

}  // namespace mpm
