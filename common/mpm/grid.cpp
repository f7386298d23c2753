#include "mpm/grid.hpp"

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
UniformGrid<D>::UniformGrid(const Lattice& lattice, const BoundarySpec& boundary)
    : Base(lattice), lattice_(lattice), boundary_(boundary) {
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
  clean_ = false;  // the arrays now mean other nodes: clear them all next time
  m.resize(s);
  v.resize(s);
  a.resize(s);
  if (!v_remap.empty()) v_remap.resize(s);
  if (!rigid.empty()) rigid.resize(s);

  // Nodes on constrained domain faces that the window reaches.
  fixed_.clear();
  slip_.clear();
  for (int face = 0; face < 2 * D; ++face) {
    const BoundaryType type = boundary_.face[face];
    if (type == BoundaryType::Free) continue;
    const int axis = face / 2;
    const int plane = (face % 2 == 0) ? 0 : cells_[axis];  // global node index of the face
    const int local = plane - lo_[axis];
    if (local < 0 || local >= nodes_[axis]) continue;
    // Enumerate the window's nodes in that plane.
    IVec<D> k = IVec<D>::Zero();
    k[axis] = local;
    const int other0 = axis == 0 ? 1 : 0;
    const int other1 = D == 3 ? (axis == 2 ? 1 : 2) : -1;
    const int n0 = nodes_[other0], n1 = other1 >= 0 ? nodes_[other1] : 1;
    for (int j = 0; j < n1; ++j)
      for (int i = 0; i < n0; ++i) {
        k[other0] = i;
        if (other1 >= 0) k[other1] = j;
        std::int64_t idx = 0;
        for (int b = 0; b < D; ++b) idx += std::int64_t(k[b]) * stride_[b];
        (type == BoundaryType::Fixed ? fixed_ : slip_).push_back({idx, face});
      }
  }
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
