#pragma once
/// Particles in cell order, grouped into bins (one per occupied cell) and chunks (runs of
/// whole slab layers with about equal particle counts). Chunks alternate in colour; two chunks
/// of one colour never touch the same node, so the particle-to-grid scatter runs all chunks of
/// one colour at once with no lock or atomic (the alternating slabs of 004, section 4.1, with
/// dynamic re-decomposition at every sort).
///
/// The chunk layout depends on the particles only, never on the thread count, and each node
/// receives its contributions in one fixed order: results are bitwise identical for any
/// number of threads.
#include <algorithm>
#include <array>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "mpm/core/columns.hpp"
#include "mpm/grid/grid.hpp"
#include "mpm/scene/particles.hpp"

namespace mpm {

struct Bin {
  std::uint32_t begin = 0, end = 0;  ///< particle range
  std::int64_t key = -1;             ///< cell key (= index of the cell's lower corner node)
  /// The cell's global index along each axis, on grids of square cells counted from the
  /// domain's origin (CellLattice): a particle is in the cell when c <= (x - origin) / h < c + 1
  /// (CellLattice::in_cell); unused elsewhere.
  std::array<double, 3> cell{};
};

struct Chunk {
  std::uint32_t bin_begin = 0, bin_end = 0;  ///< bin range
  int layer_begin = 0, layer_end = 0;        ///< slab layers [begin, end)
};

class Binning {
 public:
  /// Target number of chunks (even). More chunks balance threads better; each needs at least
  /// one slab layer.
  int target_chunks = 32;

  /// Refits the grid window to the particles, sorts the columns into cell order (stable:
  /// particles of one cell keep their relative order), drops the particles listed in
  /// `remove` (indices, any order), and rebuilds bins and chunks.
  template <class GridT>
  void sort(ColumnStore& cols, GridT& grid, const std::vector<std::uint32_t>& remove = {});

  const std::vector<Bin>& bins() const { return bins_; }
  const std::vector<Chunk>& chunks() const { return chunks_; }
  int chunk_count() const { return int(chunks_.size()); }
  /// Particle range of a chunk.
  std::uint32_t chunk_begin(int c) const { return bins_[chunks_[c].bin_begin].begin; }
  std::uint32_t chunk_end(int c) const { return bins_[chunks_[c].bin_end - 1].end; }
  long sorts() const { return sorts_; }

 private:
  std::vector<Bin> bins_;
  std::vector<Chunk> chunks_;
  std::vector<std::uint32_t> keys_, perm_, counts_;
  long sorts_ = 0;
};

template <class GridT>
void Binning::sort(ColumnStore& cols, GridT& grid, const std::vector<std::uint32_t>& remove) {
  constexpr int D = GridT::kDim;
  ++sorts_;
  const std::size_t n = cols.size();
  // Removed particles get a key past the last node; they sort last and are cut off.
  std::vector<std::uint8_t> gone;
  if (!remove.empty()) {
    gone.assign(n, 0);
    for (auto i : remove) gone[i] = 1;
  }
  // Fit the window to the particles that stay.
  const Vec<D>* x = cols.get<Vec<D>>(col::x);
  if (gone.empty()) {
    grid.fit(x, n);
  } else {
    std::vector<Vec<D>> kept;
    kept.reserve(n - remove.size());
    for (std::size_t i = 0; i < n; ++i)
      if (!gone[i]) kept.push_back(x[i]);
    grid.fit(kept.data(), kept.size());
  }
  const std::uint32_t nkeys = std::uint32_t(grid.key_count());
  keys_.resize(n);
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < n; ++i) {
    if (!gone.empty() && gone[i]) {
      keys_[i] = nkeys;
      continue;
    }
    std::int64_t key;
    Vec<D> xi;
    grid.locate(x[i], key, xi);
    keys_[i] = std::uint32_t(key);
  }
  // Stable counting sort by key.
  counts_.assign(std::size_t(nkeys) + 2, 0);
  for (std::size_t i = 0; i < n; ++i) ++counts_[keys_[i] + 1];
  for (std::size_t k = 1; k < counts_.size(); ++k) counts_[k] += counts_[k - 1];
  perm_.resize(n);
  for (std::size_t i = 0; i < n; ++i) perm_[counts_[keys_[i]]++] = std::uint32_t(i);
  const std::size_t kept = n - remove.size();
  perm_.resize(kept);
  bool identity = kept == n;
  for (std::size_t i = 0; identity && i < kept; ++i) identity = perm_[i] == i;
  if (!identity) cols.gather(perm_);

  // Bins: runs of equal keys (a bin's cell: its first particle's).
  bins_.clear();
  const Vec<D>* xs = cols.get<Vec<D>>(col::x);
  for (std::size_t i = 0; i < kept; ++i) {
    const std::uint32_t k = keys_[perm_[i]];
    if (bins_.empty() || bins_.back().key != k) {
      bins_.push_back({std::uint32_t(i), std::uint32_t(i), k});
      if constexpr (std::is_base_of_v<CellLattice<D>, GridT>) {
        IVec<D> cell;
        Vec<D> xi;
        grid.CellLattice<D>::locate(xs[i], cell, xi);
        for (int a = 0; a < D; ++a) bins_.back().cell[std::size_t(a)] = cell[a];
      }
    }
    bins_.back().end = std::uint32_t(i + 1);
  }

  // Chunks: whole slab layers, about kept / target particles each.
  chunks_.clear();
  if (bins_.empty()) return;
  const int layers = grid.layers();
  // A stencil spanning L node layers reaches L - 1 layers past its own: chunks of at least
  // that many layers keep two chunks of one colour from sharing a node.
  constexpr int kMinLayers = [] {
    if constexpr (requires { GridT::kStencilLayers; }) return GridT::kStencilLayers - 1;
    return 1;
  }();
  const int target = std::max(1, std::min(target_chunks, layers / kMinLayers));
  const double per_chunk = double(kept) / target;
  Chunk cur;
  cur.bin_begin = 0;
  cur.layer_begin = grid.layer(bins_[0].key);
  std::size_t done = 0;  // particles in closed chunks and the current one
  for (std::uint32_t b = 0; b < bins_.size(); ++b) {
    const int layer = grid.layer(bins_[b].key);
    // Close the current chunk at a layer boundary once it holds its share.
    const bool apart = kMinLayers == 1 ? layer != grid.layer(bins_[cur.bin_begin].key)
                                       : layer - cur.layer_begin >= kMinLayers;
    if (apart && b > cur.bin_begin && grid.layer(bins_[b - 1].key) != layer &&
        double(done) >= per_chunk * double(chunks_.size() + 1) &&
        int(chunks_.size()) + 1 < target) {
      cur.bin_end = b;
      cur.layer_end = layer;
      chunks_.push_back(cur);
      cur = Chunk{};
      cur.bin_begin = b;
      cur.layer_begin = layer;
    }
    done += bins_[b].end - bins_[b].begin;
  }
  cur.bin_end = std::uint32_t(bins_.size());
  cur.layer_end = grid.layer(bins_.back().key) + 1;
  chunks_.push_back(cur);
}

}  // namespace mpm
