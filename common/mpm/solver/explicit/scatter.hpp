#pragma once
/// The particle-to-grid scatters of the explicit solver: how particles add into nodes that
/// other particles share, without locks or atomics (ScatterStrategy), one function per
/// strategy. A scatter kernel (p2g, the remap of g2p) gives two bodies:
///   bin_body(chunk, bin, target, strays) runs one bin with its cell's nodes cached in
///     registers; a particle outside its bin's slab layer goes to `strays` (when not null),
///   particle_body(i, target, first_visit, unit) runs particle i alone: the strays afterwards
///     (first_visit false), and every particle of the patch strategy (first_visit: its own
///     update is still to do; unit: its patch).
#include <omp.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "mpm/core/error.hpp"
#include "mpm/core/types.hpp"
#include "mpm/grid/binning.hpp"
#include "mpm/grid/grid.hpp"

namespace mpm {

/// How the particle-to-grid scatters avoid write races without locks or atomics.
enum class ScatterStrategy {
  Colored,         ///< default: cell-ordered chunks of slab layers in two colours, balanced by
                   ///< particle count; the same bits for any thread count
  LRSlabs,         ///< 004, section 4.1: one slab set per thread, each split into L and R
                   ///< parts run alternately with a barrier between; re-balanced at every sort
  ArrayExpansion,  ///< 000, section 4.1.1: thread-private node arrays, summed after
  Patch,           ///< 000, section 4.1.2: uniform patches (slabs), one per thread, particles
                   ///< indexed per patch (Pindex/patnp) each scatter, patches assembled after
};
/// "colored", "lr-slabs", "array-expansion", "patch".
std::string to_string(ScatterStrategy s);
/// Parses a strategy name; throws InputError(where, ...) listing the names when unknown.
ScatterStrategy parse_strategy(const std::string& name, const std::string& where);

/// The node fields a scatter writes (bits).
enum ScatterFields : int { kMass = 1, kMomentum = 2, kForce = 4, kRemap = 8 };

/// Node arrays a scatter writes into; node n is element n - offset.
template <int D>
struct ScatterTarget {
  double* m;
  Vec<D>* v;  ///< momentum
  Vec<D>* a;  ///< force
  Vec<D>* q;  ///< remapped momentum
  std::int64_t offset;
};

template <Grid GridT>
class Scatter {
 public:
  static constexpr int D = GridT::kDim;
  using Target = ScatterTarget<D>;

  explicit Scatter(ScatterStrategy strategy)
      : strategy_(strategy), strays_(omp_get_max_threads()) {}
  ScatterStrategy strategy() const { return strategy_; }
  /// Bytes of the private node arrays and the patch index.
  std::size_t bytes() const;

  /// Adds the `fields` (ScatterFields) of every particle into the grid's node data, by the
  /// strategy; x holds the n particles' positions (the patch strategy indexes them).
  template <class BinBody, class ParticleBody>
  void run(int fields, GridT& grid, const Binning& binning, const Vec<D>* x, std::size_t n,
           BinBody&& bin_body, ParticleBody&& particle_body) {
    switch (strategy_) {
      case ScatterStrategy::Colored:
        colored(grid, binning, bin_body, particle_body);
        break;
      case ScatterStrategy::LRSlabs:
        lr_slabs(grid, binning, bin_body, particle_body);
        break;
      case ScatterStrategy::ArrayExpansion:
        array_expansion(fields, grid, binning, bin_body);
        break;
      case ScatterStrategy::Patch:
        patch(fields, grid, x, n, particle_body);
        break;
    }
  }

 private:
  /// Private node arrays of one thread (array expansion) or one patch.
  struct PrivateGrid {
    std::vector<double> m;
    std::vector<Vec<D>> v, a, q;
    std::int64_t offset = 0, size = 0;
    /// Zeroes the fields a scatter writes.
    void clear(int fields);
    Target target() { return Target{m.data(), v.data(), a.data(), q.data(), offset}; }
    /// Adds its fields at node n into the grid.
    [[gnu::always_inline]] void add_to(GridT& grid, int fields, std::int64_t n) const {
      const std::int64_t k = n - offset;
      if (fields & kMass) grid.m[n] += m[k];
      if (fields & kMomentum) grid.v[n] += v[k];
      if (fields & kForce) grid.a[n] += a[k];
      if (fields & kRemap) grid.v_remap[n] += q[k];
    }
  };
  static Target grid_target(GridT& grid) {
    return Target{grid.m.data(), grid.v.data(), grid.a.data(), grid.v_remap.data(), 0};
  }
  /// The bins of chunk ch, each by bin_body.
  template <class BinBody>
  static void run_chunk(const Binning& binning, int ch, BinBody& bin_body, const Target& t,
                        std::vector<std::uint32_t>* strays) {
    const Chunk& chunk = binning.chunks()[ch];
    for (std::uint32_t bi = chunk.bin_begin; bi < chunk.bin_end; ++bi) bin_body(ch, bi, t, strays);
  }

  template <class BinBody, class ParticleBody>
  void colored(GridT& grid, const Binning& binning, BinBody& bin_body, ParticleBody& particle_body);
  template <class BinBody, class ParticleBody>
  void lr_slabs(GridT& grid, const Binning& binning, BinBody& bin_body,
                ParticleBody& particle_body);
  template <class ParticleBody>
  void add_strays(GridT& grid, ParticleBody& particle_body);
  template <class BinBody>
  void array_expansion(int fields, GridT& grid, const Binning& binning, BinBody& bin_body);
  template <class ParticleBody>
  void patch(int fields, GridT& grid, const Vec<D>* x, std::size_t n, ParticleBody& particle_body);
  void index_patches(const GridT& grid, const Vec<D>* x, std::size_t n, int np);

  ScatterStrategy strategy_;
  std::vector<std::vector<std::uint32_t>> strays_;  ///< per thread
  std::vector<PrivateGrid> private_;  ///< array expansion: per thread; patch: per patch
  std::vector<std::vector<std::uint32_t>> pindex_;  ///< patch: particles of each patch
};

template <Grid GridT>
std::size_t Scatter<GridT>::bytes() const {
  std::size_t b = 0;
  for (const auto& g : private_)
    b += g.m.capacity() * sizeof(double) +
         (g.v.capacity() + g.a.capacity() + g.q.capacity()) * sizeof(Vec<D>);
  for (const auto& pi : pindex_) b += pi.capacity() * sizeof(std::uint32_t);
  return b;
}

template <Grid GridT>
void Scatter<GridT>::PrivateGrid::clear(int fields) {
  const std::size_t n = std::size_t(size);
  if (fields & kMass) m.assign(n, 0.0);
  if (fields & kMomentum) v.assign(n, Vec<D>::Zero());
  if (fields & kForce) a.assign(n, Vec<D>::Zero());
  if (fields & kRemap) q.assign(n, Vec<D>::Zero());
}

// Colored: two chunks of one colour never share a node, so a colour runs at a time, its
// chunks dealt to the threads as they come free (balanced by particle count); then the strays.
template <Grid GridT>
template <class BinBody, class ParticleBody>
void Scatter<GridT>::colored(GridT& grid, const Binning& binning, BinBody& bin_body,
                             ParticleBody& particle_body) {
  const Target t = grid_target(grid);
  const int nchunks = binning.chunk_count();
#pragma omp parallel
  {
    std::vector<std::uint32_t>* strays = &strays_[omp_get_thread_num()];
    for (int color = 0; color < 2; ++color) {
#pragma omp for schedule(dynamic, 1)
      for (int ch = color; ch < nchunks; ch += 2) run_chunk(binning, ch, bin_body, t, strays);
    }
  }
  add_strays(grid, particle_body);
}

// LR slabs (004, section 4.1): thread t runs the chunks 2t (its L part) and 2t + 1 (its R
// part; 2t + 2T ... when there are more chunks than threads), every L part before every R
// part; then the strays.
template <Grid GridT>
template <class BinBody, class ParticleBody>
void Scatter<GridT>::lr_slabs(GridT& grid, const Binning& binning, BinBody& bin_body,
                              ParticleBody& particle_body) {
#pragma omp parallel
  {
    const int me = omp_get_thread_num(), threads = omp_get_num_threads();
    for (int part = 0; part < 2; ++part) {
      for (int ch = part + 2 * me; ch < binning.chunk_count(); ch += 2 * threads)
        run_chunk(binning, ch, bin_body, grid_target(grid), &strays_[me]);
#pragma omp barrier
    }
  }
  add_strays(grid, particle_body);
}

// The particles that left their bin's slab layer, serially in particle order.
template <Grid GridT>
template <class ParticleBody>
void Scatter<GridT>::add_strays(GridT& grid, ParticleBody& particle_body) {
  std::vector<std::uint32_t> all;
  for (auto& st : strays_) {
    all.insert(all.end(), st.begin(), st.end());
    st.clear();
  }
  std::sort(all.begin(), all.end());
  const Target t = grid_target(grid);
  for (auto i : all) particle_body(i, t, false, -1);
}

// Array expansion (000, section 4.1.1): each thread scatters into its own copy of the node
// arrays; the copies are summed after.
template <Grid GridT>
template <class BinBody>
void Scatter<GridT>::array_expansion(int fields, GridT& grid, const Binning& binning,
                                     BinBody& bin_body) {
  const int threads = omp_get_max_threads();
  private_.resize(threads);
  const std::int64_t n = std::int64_t(grid.nodes());
  const int nchunks = binning.chunk_count();
#pragma omp parallel
  {
    PrivateGrid& mine = private_[omp_get_thread_num()];
    mine.offset = 0;
    mine.size = n;
    mine.clear(fields);
    const Target t = mine.target();
#pragma omp for schedule(static)
    for (int ch = 0; ch < nchunks; ++ch) run_chunk(binning, ch, bin_body, t, nullptr);
      // A(:) = sum_j A_list(:, j) (000, eq. 16), in thread order at every node.
#pragma omp for schedule(static)
    for (std::int64_t node = 0; node < n; ++node)
      for (int j = 0; j < threads; ++j) private_[j].add_to(grid, fields, node);
  }
}

// Patch (000, section 4.1.2): uniform patches along the slab axis, one per thread, each
// scattering its particles into its own node arrays; the patches are assembled after.
template <Grid GridT>
template <class ParticleBody>
void Scatter<GridT>::patch(int fields, GridT& grid, const Vec<D>* x, std::size_t n,
                           ParticleBody& particle_body) {
  if constexpr (requires { grid.layer_stride(); }) {
    const int np = omp_get_max_threads();
    const int layers = grid.layers();
    const std::int64_t S = grid.layer_stride();
    index_patches(grid, x, n, np);
    private_.resize(np);
#pragma omp parallel for schedule(static, 1)
    for (int pp = 0; pp < np; ++pp) {
      PrivateGrid& g = private_[pp];
      const std::int64_t l0 = std::int64_t(pp) * layers / np,
                         l1 = std::int64_t(pp + 1) * layers / np;
      g.offset = l0 * S;
      g.size = std::min<std::int64_t>((l1 + 1) * S, std::int64_t(grid.nodes())) - g.offset;
      g.clear(fields);
      const Target t = g.target();
      for (auto i : pindex_[pp]) particle_body(i, t, true, pp);
    }
    // Assemble the patches into the grid, patch by patch (neighbours share a node layer).
    for (int pp = 0; pp < np; ++pp) {
      const PrivateGrid& g = private_[pp];
#pragma omp parallel for schedule(static)
      for (std::int64_t k = 0; k < g.size; ++k) g.add_to(grid, fields, g.offset + k);
    }
  } else {
    throw InputError("--strategy", "the patch strategy needs a uniform grid");
  }
}

// Pindex and patnp of the patch strategy (000, section 4.1.2), rebuilt each scatter from the
// particles' current cells, in parallel: patnp_th(j, p) counts particles of patch p in
// thread j's share. Patch pp holds the cell layers [pp layers / np, (pp + 1) layers / np).
template <Grid GridT>
void Scatter<GridT>::index_patches(const GridT& grid, const Vec<D>* x, std::size_t n, int np) {
  const int layers = grid.layers();
  std::vector<std::uint16_t> patch_of(n);
  std::vector<std::vector<std::size_t>> patnp_th(np, std::vector<std::size_t>(np, 0));
  std::vector<std::uint16_t> patch_of_layer(layers);
  for (int pp = 0; pp < np; ++pp)
    for (int l = pp * layers / np; l < (pp + 1) * layers / np; ++l)
      patch_of_layer[l] = std::uint16_t(pp);
  pindex_.resize(np);
#pragma omp parallel
  {
    const int j = omp_get_thread_num();
#pragma omp for schedule(static)
    for (std::size_t i = 0; i < n; ++i) {
      std::int64_t key;
      Vec<D> xi;
      grid.locate(x[i], key, xi);
      const int pp = patch_of_layer[grid.layer(key)];
      patch_of[i] = std::uint16_t(pp);
      ++patnp_th[j][pp];
    }
#pragma omp single
    for (int pp = 0; pp < np; ++pp) {
      std::size_t patnp = 0;
      for (int jj = 0; jj < np; ++jj) {
        const std::size_t c = patnp_th[jj][pp];
        patnp_th[jj][pp] = patnp;  // becomes thread jj's first slot in Pindex(:, pp)
        patnp += c;
      }
      pindex_[pp].resize(patnp);
    }
#pragma omp for schedule(static)
    for (std::size_t i = 0; i < n; ++i)
      pindex_[patch_of[i]][patnp_th[j][patch_of[i]]++] = std::uint32_t(i);
  }
}

}  // namespace mpm
