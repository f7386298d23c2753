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
#include <cstdint>
#include <vector>

#include "mpm/columns.hpp"
#include "mpm/grid.hpp"

namespace mpm {

struct Bin {
  std::uint32_t begin = 0, end = 0;  ///< particle range
  std::int64_t key = -1;             ///< cell key (= index of the cell's lower corner node)
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
  template <int D>
  void sort(ColumnStore& cols, Grid<D>& grid, const std::vector<std::uint32_t>& remove = {});

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

}  // namespace mpm
