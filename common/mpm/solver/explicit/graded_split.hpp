#pragma once
// Particle splitting on graded grids (004, section 3.3): a particle whose spacing is that of a
// coarser level than the cell it has moved into splits into 2^D children of the finer level,
// so that no fine cell between two coarse particles stays empty ("numerical fracture",
// 004 Fig. 8).
//
// Parallel, with no serial pass over the particles and no lock (004, section 4.3 ran this step
// serially because it appends to the particle list):
//   1. a parallel scan finds the particles to split, in fixed blocks of particles, and (when
//      the level boxes follow a body) the body's mass centre;
//   2. the block counts give, by a prefix sum over the blocks, each split its slots: child 0
//      replaces its parent, children 1..2^D-1 go to the end of the columns;
//   3. a parallel loop over the splits writes the children, each to its own slots.
// The children are appended out of cell order, so the step asks for a re-sort, which the next
// step does before its first kernel: particles stay in cell order for every kernel. A sort
// costs a pass over every column, so splits wait for the next sort the solver makes anyway
// (particles that crossed cells), for at most kSplitWait steps, or until they are many: a
// coarse particle spends a few more steps in a fine cell, moving by a fraction of a cell
// (cfl = 0.5 bounds a step's motion by half a cell; at 190 m/s in copper a step moves 1/50 of
// a cell), with no gap behind it since coarse particles are one fine cell apart at 2 per cell.
// Blocks, slots and ids do not depend on the thread count, so results stay bitwise
// reproducible.
#include <cmath>
#include <cstring>
#include <limits>

#include "mpm/solver/explicit/explicit_solver.hpp"

namespace mpm {

/// The particles to split, found by the scan in fixed blocks of particles.
template <Grid GridT>
struct ExplicitSolver<GridT>::SplitScan {
  static constexpr int kKids = 1 << D;            ///< children of a split
  static constexpr std::size_t kSpan = 8192;      ///< particles per scan block
  std::vector<std::vector<std::uint32_t>> found;  ///< by block, in particle order
  std::vector<std::size_t> first;                 ///< by block: its first split's index; count
  std::size_t count() const { return first.back(); }
};

template <Grid GridT>
void ExplicitSolver<GridT>::split_particles() requires GridT::kGraded {
  ScopedTimer timer(timers_, timers_.id("split_particles"));
  constexpr int kKids = SplitScan::kKids;
  const std::size_t n = particles_.size();
  const SplitScan scan = scan_for_splits();
  const std::size_t k = scan.count();
  if (k == 0) return;
  constexpr int kSplitWait = 10;  // steps
  if (!need_sort_ && split_wait_ < kSplitWait && k * 200 < n) {
    ++split_wait_;
    return;
  }
  split_wait_ = 0;
  if (n + k * (kKids - 1) > std::numeric_limits<std::uint32_t>::max())
    throw InstabilityError(steps_ + 1, time_ + dt_, -1,
                           "particle splitting would exceed 2^32 particles; use fewer levels");
  if (next_id_ == 0) {
    const ParticleView<D> p = view<D>(particles_);
    std::uint32_t top = 0;
#pragma omp parallel for reduction(max : top) schedule(static)
    for (std::size_t i = 0; i < n; ++i) top = std::max(top, p.id[i]);
    next_id_ = top + 1;
  }
  if (std::uint64_t(next_id_) + k * (kKids - 1) > std::numeric_limits<std::uint32_t>::max())
    throw InstabilityError(steps_ + 1, time_ + dt_, -1, "particle ids exceed 2^32 after splitting");
  write_children(scan, n);
  next_id_ += std::uint32_t(k * (kKids - 1));
  split_count_ += long(k);
  need_sort_ = true;  // children were appended: back to cell order before the next kernel
}

/// 1. Scan: particles coarser than the level box they are in; the followed body's moments
/// (a move of the boxes asks for a sort: the grid rebuilds then). 2. Slots: split j (in
/// particle order) writes children 1.. to n + (kKids - 1) j + ....
template <Grid GridT>
auto ExplicitSolver<GridT>::scan_for_splits() -> SplitScan requires GridT::kGraded {
  constexpr std::size_t kSpan = SplitScan::kSpan;
  const ParticleView<D> p = view<D>(particles_);
  std::uint8_t* level = particles_.template get<std::uint8_t>(col::level);
  const std::size_t n = p.n;
  const std::size_t nblocks = (n + kSpan - 1) / kSpan;
  const int follow = grid_.followed_body();
  SplitScan scan;
  scan.found.resize(nblocks);
  std::vector<double> mass(nblocks, 0.0);
  std::vector<Vec<D>> moment(nblocks, Vec<D>::Zero());
#pragma omp parallel for schedule(dynamic, 4)
  for (long b = 0; b < long(nblocks); ++b) {
    const std::size_t i0 = std::size_t(b) * kSpan, i1 = std::min(n, i0 + kSpan);
    for (std::size_t i = i0; i < i1; ++i) {
      if (level[i] == 0) {  // not yet known: the level the particle starts in
        level[i] = std::uint8_t(std::max(1, grid_.level_at(p.x[i])));
        continue;
      }
      // Rebar nodes are not split: their elements link them, not the grid (004, section 3.3).
      if (grid_.in_finer(p.x[i], level[i]) && p.material[i] != kRebarNode)
        scan.found[b].push_back(std::uint32_t(i));
      if (follow >= 0 && p.body[i] == follow) {
        mass[b] += p.m[i];
        moment[b] += p.m[i] * p.x[i];
      }
    }
  }
  if (follow >= 0) {
    double M = 0;
    Vec<D> S = Vec<D>::Zero();
    for (std::size_t b = 0; b < nblocks; ++b) M += mass[b], S += moment[b];
    if (M > 0 && grid_.follow(S / M)) need_sort_ = true;  // the grid rebuilds at the sort
  }
  scan.first.assign(nblocks + 1, 0);
  for (std::size_t b = 0; b < nblocks; ++b)
    scan.first[b + 1] = scan.first[b] + scan.found[b].size();
  return scan;
}

/// 3. Children, each split to its own slots: the columns grow from n particles, child 0
/// replaces its parent.
template <Grid GridT>
void ExplicitSolver<GridT>::write_children(const SplitScan& scan,
                                           std::size_t n) requires GridT::kGraded {
  constexpr int kKids = SplitScan::kKids;
  particles_.resize(n + scan.count() * (kKids - 1));
  const ParticleView<D> p = view<D>(particles_);
  material_ = p.material;
  std::uint8_t* level = particles_.template get<std::uint8_t>(col::level);
  struct Bytes {
    std::byte* data;
    std::size_t size;
  };
  std::vector<Bytes> cols;
  for (Column& c : particles_.columns()) cols.push_back({c.data(), c.info().element_bytes()});
  std::vector<double> spacing(scene_.bodies.size());  // per body: h1 / particles per cell
  for (std::size_t b = 0; b < spacing.size(); ++b)
    spacing[b] = scene_.bodies[b].spacing(grid_.level_h(1));
  const Vec<D> lo = grid_.domain_min(), hi = grid_.domain_max();
  const double inset = 1e-9 * grid_.min_cell_size();
  const std::uint32_t id0 = next_id_;
  const long nblocks = long(scan.found.size());
#pragma omp parallel for schedule(dynamic, 4)
  for (long b = 0; b < nblocks; ++b) {
    for (std::size_t q = 0; q < scan.found[b].size(); ++q) {
      const std::size_t j = scan.first[b] + q;
      const std::uint32_t i = scan.found[b][q];
      const std::size_t slot = n + j * (kKids - 1);  // child c >= 1 at slot + c - 1
      // Children 1..: copies of the parent: velocity, stress, strain, specific energy,
      // plastic strain, temperature and every history variable (004, section 3.3).
      for (const Bytes& c : cols)
        for (int kid = 1; kid < kKids; ++kid)
          std::memcpy(c.data + (slot + kid - 1) * c.size, c.data + std::size_t(i) * c.size, c.size);
      // Positions: the centres of the 2^D equal parts of the parent's current extent
      // L_a = L0 (1 + eps_a) (004, eq. 23), with eps_a the engineering strain exp(strain_a) - 1
      // and L0 the spacing the particle was made with.
      const double L0 = std::ldexp(spacing[p.body[i]], -(int(level[i]) - 1));
      Vec<D> quarter;
      for (int a = 0; a < D; ++a) quarter[a] = 0.25 * L0 * std::exp(p.strain[i][a]);
      const Vec<D> x_p = p.x[i];
      const double m_kid = p.m[i] / kKids;  // exact: a power of two
      const std::uint8_t level_kid = std::uint8_t(level[i] + 1);
      for (int kid = kKids - 1; kid >= 0; --kid) {  // child 0 last: it overwrites the parent
        const std::size_t c = kid == 0 ? i : slot + kid - 1;
        Vec<D> x = x_p;
        for (int a = 0; a < D; ++a) {
          x[a] += ((kid >> a) & 1) ? quarter[a] : -quarter[a];
          x[a] = std::clamp(x[a], lo[a] + inset, hi[a] - inset);
        }
        p.x[c] = x;
        p.m[c] = m_kid;  // mass and volume m / rho split evenly; so is m e, e being specific
        if (p.f_ext) p.f_ext[c] = p.f_ext[i] / kKids;  // a load keeps its total
        level[c] = level_kid;
        if (kid > 0) p.id[c] = id0 + std::uint32_t(j * (kKids - 1) + kid - 1);
      }
    }
  }
}

}  // namespace mpm
