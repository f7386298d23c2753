#include "mpm/grid/sparse_grid.hpp"

#include <omp.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <limits>
#include <stdexcept>
#include <string>

namespace mpm {

template <int D>
SparseGrid<D>::SparseGrid(const Lattice& lattice, const BoundarySpec& boundary)
    : Base(lattice), GridNodes<D>(boundary) {
  for (int a = 0; a < D; ++a) lo_[a] = 0, hi_[a] = -1;
}

namespace {

/// A box of D axes stored flat, axis order[0] fastest. Extents of unused axes (2D) are 1.
struct Box {
  std::array<int, 3> ext{1, 1, 1};  ///< extent along order[0], order[1], order[2]
  std::array<std::size_t, 3> stride{1, 1, 1};
  std::size_t size() const { return std::size_t(ext[0]) * ext[1] * ext[2]; }
};

/// out[k] = in[k] | in[k - s] (| in[k + s] when `both`) along the box's axis q, where the
/// neighbour exists: a dilation by one along one axis. No divisions; the inner loops are
/// contiguous.
void dilate(const Box& b, int q, bool both, const std::vector<std::uint8_t>& in,
            std::vector<std::uint8_t>& out) {
  const std::size_t s = b.stride[q];
  const std::int64_t e = b.ext[q];
  const std::int64_t blocks = std::int64_t(b.size() / (s * std::size_t(e)));
#pragma omp parallel for collapse(2) schedule(static)
  for (std::int64_t blk = 0; blk < blocks; ++blk)
    for (std::int64_t c = 0; c < e; ++c) {
      const std::size_t k0 = std::size_t(blk) * s * std::size_t(e) + std::size_t(c) * s;
      const std::uint8_t* mid = &in[k0];
      const std::uint8_t* lo = c > 0 ? &in[k0 - s] : nullptr;
      const std::uint8_t* hi = both && c + 1 < e ? &in[k0 + s] : nullptr;
      std::uint8_t* o = &out[k0];
      for (std::size_t r = 0; r < s; ++r)
        o[r] = std::uint8_t(mid[r] | (lo ? lo[r] : 0) | (hi ? hi[r] : 0));
    }
}

/// ids[k] = running number of the flagged entries in index order, -1 for the others; returns
/// the count. Two parallel passes (count per part, then number).
std::size_t number_flags(const std::vector<std::uint8_t>& flag, std::vector<std::int32_t>& ids) {
  const std::size_t n = flag.size();
  ids.resize(n);
  const int parts = 4 * omp_get_max_threads();
  std::vector<std::size_t> first(std::size_t(parts) + 1, 0);
#pragma omp parallel for schedule(static)
  for (int p = 0; p < parts; ++p) {
    std::size_t c = 0;
    for (std::size_t k = n * std::size_t(p) / parts; k < n * std::size_t(p + 1) / parts; ++k)
      c += flag[k];
    first[std::size_t(p) + 1] = c;
  }
  for (int p = 0; p < parts; ++p) first[std::size_t(p) + 1] += first[std::size_t(p)];
  if (first[std::size_t(parts)] > std::size_t(std::numeric_limits<std::int32_t>::max()))
    throw std::runtime_error("sparse grid of " + std::to_string(first[std::size_t(parts)]) +
                             " cells or nodes exceeds 2^31; use larger cells");
#pragma omp parallel for schedule(static)
  for (int p = 0; p < parts; ++p) {
    std::int32_t next = std::int32_t(first[std::size_t(p)]);
    for (std::size_t k = n * std::size_t(p) / parts; k < n * std::size_t(p + 1) / parts; ++k)
      ids[k] = flag[k] ? next++ : -1;
  }
  return first[std::size_t(parts)];
}

}  // namespace

template <int D>
void SparseGrid<D>::fit(const Vec<D>* x, std::size_t n, int margin) {
  // The box: the particles' cells widened by the margin, as the dense window; its slab axis.
  IVec<D> ext;
  slab_ = this->particle_box(x, n, margin, lo_, hi_);
  for (int a = 0; a < D; ++a) ext[a] = hi_[a] - lo_[a] + 1;
  // The flat order: the other axes fastest in increasing order, the slab axis slowest.
  std::array<int, 3> order{0, 0, 0};
  {
    int q = 0;
    for (int a = 0; a < D; ++a)
      if (a != slab_) order[q++] = a;
    order[q] = slab_;
  }
  Box cb, nb;  // cells and nodes of the box
  for (int q = 0; q < D; ++q) cb.ext[q] = ext[order[q]], nb.ext[q] = ext[order[q]] + 1;
  for (int q = 1; q < 3; ++q) {
    cb.stride[q] = cb.stride[q - 1] * std::size_t(cb.ext[q - 1]);
    nb.stride[q] = nb.stride[q - 1] * std::size_t(nb.ext[q - 1]);
  }
  for (int q = 0; q < D; ++q) stride_[order[q]] = cb.stride[q];
  const std::size_t box = cb.size(), nbox = nb.size();

  // Occupied cells (a byte each), widened by the margin along each axis in turn.
  std::vector<std::uint8_t> occ(box, 0), tmp(box);
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < n; ++i) {
    IVec<D> cell;
    Vec<D> xi;
    locate(x[i], cell, xi);
    std::atomic_ref<std::uint8_t>(occ[box_index(cell)]).store(1, std::memory_order_relaxed);
  }
  for (int r = 0; r < margin; ++r)
    for (int q = 0; q < D; ++q) {
      dilate(cb, q, true, occ, tmp);
      occ.swap(tmp);
    }
  const std::size_t keys = number_flags(occ, cell_key_);

  // Active nodes: the corners of active cells, i.e. the cells moved into the node box and
  // dilated by one towards +1 along each axis; numbered in the node box's order.
  std::vector<std::uint8_t> nodes_on(nbox, 0), ntmp(nbox);
#pragma omp parallel for collapse(2) schedule(static)
  for (int c2 = 0; c2 < cb.ext[2]; ++c2)
    for (int c1 = 0; c1 < cb.ext[1]; ++c1) {
      const std::uint8_t* row = &occ[c2 * cb.stride[2] + c1 * cb.stride[1]];
      std::uint8_t* out = &nodes_on[c2 * nb.stride[2] + c1 * nb.stride[1]];
      for (int c0 = 0; c0 < cb.ext[0]; ++c0) out[c0] = row[c0];
    }
  std::vector<std::uint8_t>().swap(occ);
  std::vector<std::uint8_t>().swap(tmp);
  for (int q = 0; q < D; ++q) {
    dilate(nb, q, false, nodes_on, ntmp);
    nodes_on.swap(ntmp);
  }
  std::vector<std::uint8_t>().swap(ntmp);
  std::vector<std::int32_t> node_id;
  const std::size_t count = number_flags(nodes_on, node_id);
  std::vector<std::uint8_t>().swap(nodes_on);

  // Each active cell's corners, in the corner order of the shape functions, and its layer.
  std::array<std::size_t, kCorners<D>> corner{};
  for (int c = 0; c < kCorners<D>; ++c)
    for (int q = 0; q < D; ++q)
      if ((c >> order[q]) & 1) corner[c] += nb.stride[q];
  cell_nodes_.resize(keys * kMaxNodes);
  cell_layer_.resize(keys);
#pragma omp parallel for collapse(2) schedule(static)
  for (int c2 = 0; c2 < cb.ext[2]; ++c2)
    for (int c1 = 0; c1 < cb.ext[1]; ++c1)
      for (int c0 = 0; c0 < cb.ext[0]; ++c0) {
        const std::int32_t key = cell_key_[c2 * cb.stride[2] + c1 * cb.stride[1] + std::size_t(c0)];
        if (key < 0) continue;
        const std::size_t base = c2 * nb.stride[2] + c1 * nb.stride[1] + std::size_t(c0);
        std::int32_t* out = &cell_nodes_[std::size_t(key) * kMaxNodes];
        for (int c = 0; c < kCorners<D>; ++c) out[c] = node_id[base + corner[c]];
        cell_layer_[std::size_t(key)] = D == 3 ? c2 : c1;  // the slab axis is the slowest
      }

  this->resize_nodes(count);
  // Active nodes on constrained domain faces, in the dense window's order.
  std::array<std::size_t, D> nstride{};
  IVec<D> nodes_per_axis;
  for (int q = 0; q < D; ++q) nstride[order[q]] = nb.stride[q];
  for (int a = 0; a < D; ++a) nodes_per_axis[a] = ext[a] + 1;
  this->collect_face_nodes(cells_, lo_, nodes_per_axis, [&](const IVec<D>& k) {
    std::size_t idx = 0;
    for (int a = 0; a < D; ++a) idx += std::size_t(k[a]) * nstride[a];
    return std::int64_t(node_id[idx]);
  });
}

template class SparseGrid<2>;
template class SparseGrid<3>;

}  // namespace mpm
