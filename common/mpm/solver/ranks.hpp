#pragma once
/// Domain decomposition of the explicit solver across the ranks of an MPI run (Comm): each
/// rank holds the particles of one slab of cells along the longest axis of all the particles'
/// box, the slabs cut at equal particle counts whenever the particles are re-sorted (so the
/// cuts follow the material), and a grid window (uniform or sparse) fitted to its own
/// particles. Windows of neighbouring ranks overlap in the node planes at a cut; after every
/// scatter those shared nodes are summed across the ranks that hold them, in rank order, so
/// that every holder has the same bits and each rank's particles see the grid a single process
/// would, to round-off. Particles that crossed a cut go to their new rank at the sort with all
/// their columns. No particle is ever held twice, so particle sums (energies, momentum) are
/// the ranks' sums added in rank order.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "mpm/core/columns.hpp"
#include "mpm/core/comm.hpp"
#include "mpm/core/types.hpp"
#include "mpm/scene/particles.hpp"

namespace mpm {

/// Newline-separated fields of a text, read one after the other (messages between ranks).
class Fields {
 public:
  explicit Fields(const std::string& text) : text_(text) {}
  bool done() const { return at_ >= text_.size(); }
  std::string next() {
    const std::size_t end = text_.find('\n', at_);
    std::string s = text_.substr(at_, end - at_);
    at_ = end == std::string::npos ? text_.size() : end + 1;
    return s;
  }
  /// What is left, newlines and all.
  std::string rest() const { return done() ? std::string() : text_.substr(at_); }

 private:
  const std::string& text_;
  std::size_t at_ = 0;
};

/// Rows `rows` of every column of a store, column after column (the receiver has the same
/// columns in the same order), appended to `out`.
void pack_rows(const ColumnStore& cols, const std::vector<std::uint32_t>& rows, std::string& out);
/// Every row, the same way: each column's bytes as they are.
void pack_columns(const ColumnStore& cols, std::string& out);
/// Appends rows packed by pack_rows or pack_columns (`size` bytes at `bytes`) to a store with
/// the same columns.
void append_rows(ColumnStore& cols, const char* bytes, std::size_t size);
/// The columns' names, types, widths and units, for a rank that builds an empty store like it.
std::string pack_schema(const ColumnStore& cols);
/// Adds the columns pack_schema described to an empty store.
void add_schema(ColumnStore& cols, const std::string& schema);
/// Every rank's rows gathered at the root (in rank order, then put in particle-id order);
/// empty elsewhere. `out` gets the columns of `cols`.
void gather_by_id(const Comm& comm, const ColumnStore& cols, ColumnStore& out);

/// The slab decomposition of one explicit solver's particles and grid (GridT: UniformGrid or
/// SparseGrid: node_box and node_at).
template <class GridT>
class RankSlabs {
 public:
  static constexpr int D = GridT::kDim;

  explicit RankSlabs(const Comm& comm) : comm_(comm) {}

  /// Re-cuts the slabs at equal particle counts along the longest axis of all the particles'
  /// box and sends every particle that is not in this rank's slab to its rank (with all its
  /// columns); the received ones are appended. Particles `gone` (sorted: they left the domain)
  /// stay out of it. Returns the rows to drop, `gone` and the ones sent away (sorted), for the
  /// sort that follows, which also puts the received ones in cell order.
  std::vector<std::uint32_t> migrate(ColumnStore& particles, const GridT& grid,
                                     const std::vector<std::uint32_t>& gone) {
    const ParticleView<D> p = view<D>(particles);
    const std::size_t n = p.n;
    std::vector<std::uint8_t> out(n, 0);
    for (auto i : gone) out[i] = 1;
    // All particles' cell box and its longest axis.
    IVec<D> lo = IVec<D>::Constant(std::numeric_limits<int>::max()), hi = -lo;
    std::vector<IVec<D>> cell(n);
    const Vec<D> origin = grid.origin();
    const double inv_h = grid.inv_h();
    for (std::size_t i = 0; i < n; ++i) {
      for (int a = 0; a < D; ++a) cell[i][a] = int(std::floor((p.x[i][a] - origin[a]) * inv_h));
      if (!out[i]) lo = lo.cwiseMin(cell[i]), hi = hi.cwiseMax(cell[i]);
    }
    for (int a = 0; a < D; ++a) lo[a] = int(-comm_.max(-lo[a])), hi[a] = int(comm_.max(hi[a]));
    total_ = std::size_t(comm_.sum(double(n - gone.size())));
    if (total_ == 0) return gone;
    axis_ = D - 1;  // ties go to the highest axis, as the grid's slab axis
    for (int a = D - 2; a >= 0; --a)
      if (hi[a] - lo[a] > hi[axis_] - lo[axis_]) axis_ = a;
    // Particles per cell layer along it, all ranks'; cuts at equal counts.
    const int layers = hi[axis_] - lo[axis_] + 1;
    std::vector<double> count(std::size_t(layers), 0.0);
    for (std::size_t i = 0; i < n; ++i)
      if (!out[i]) count[std::size_t(cell[i][axis_] - lo[axis_])] += 1;
    comm_.sum(count.data(), layers);
    const int P = comm_.size();
    cut_.assign(std::size_t(P) + 1, 0);
    cut_[0] = std::numeric_limits<int>::min(),
    cut_[std::size_t(P)] = std::numeric_limits<int>::max();
    double below = 0;
    int r = 1;
    for (int l = 0; l < layers && r < P; ++l) {
      while (r < P && below >= double(total_) * r / P) cut_[std::size_t(r++)] = lo[axis_] + l;
      below += count[std::size_t(l)];
    }
    while (r < P) cut_[std::size_t(r++)] = hi[axis_] + 1;
    // Who goes where.
    std::vector<std::vector<std::uint32_t>> to(static_cast<std::size_t>(P));
    for (std::size_t i = 0; i < n; ++i) {
      if (out[i]) continue;
      const int dest = owner(cell[i][axis_]);
      if (dest != comm_.rank()) to[std::size_t(dest)].push_back(std::uint32_t(i)), out[i] = 1;
    }
    std::vector<std::string> send(static_cast<std::size_t>(P));
    for (int q = 0; q < P; ++q)
      if (q != comm_.rank()) pack_rows(particles, to[std::size_t(q)], send[std::size_t(q)]);
    std::vector<std::string> got = comm_.all_to_all(std::move(send));
    std::vector<std::uint32_t> drop;
    for (std::size_t i = 0; i < n; ++i)
      if (out[i]) drop.push_back(std::uint32_t(i));
    migrated_ += double(drop.size() - gone.size());
    for (int q = 0; q < P; ++q)
      if (q != comm_.rank())
        append_rows(particles, got[std::size_t(q)].data(), got[std::size_t(q)].size());
    return drop;
  }

  /// After the grid was fitted to this rank's particles: the nodes its window shares with
  /// each other rank's window, in an order both agree on, and which of its nodes it owns (a
  /// shared node is owned by the lowest rank holding it: it alone counts it in node sums such
  /// as the forces on the supports).
  void share_nodes(const GridT& grid) {
    IVec<D> lo, hi;
    grid.node_box(lo, hi);
    std::string mine(reinterpret_cast<const char*>(lo.data()), sizeof(int) * D);
    mine.append(reinterpret_cast<const char*>(hi.data()), sizeof(int) * D);
    const std::vector<std::string> boxes = comm_.all_gather(mine);
    partners_.clear();
    shared_.clear();
    std::vector<std::string> send(std::size_t(comm_.size()));
    std::vector<std::vector<std::int64_t>> local(std::size_t(comm_.size()));
    for (int q = 0; q < comm_.size(); ++q) {
      if (q == comm_.rank()) continue;
      IVec<D> qlo, qhi;
      std::memcpy(qlo.data(), boxes[std::size_t(q)].data(), sizeof(int) * D);
      std::memcpy(qhi.data(), boxes[std::size_t(q)].data() + sizeof(int) * D, sizeof(int) * D);
      const IVec<D> blo = lo.cwiseMax(qlo), bhi = hi.cwiseMin(qhi);
      if ((bhi - blo).minCoeff() < 0) continue;
      // The nodes of the overlap this rank has, by their place in the box (axis 0 fastest).
      std::vector<std::int64_t> place;
      each_node(blo, bhi, [&](const IVec<D>& k, std::int64_t at) {
        const std::int64_t node = grid.node_at(k);
        if (node >= 0) place.push_back(at), local[std::size_t(q)].push_back(node);
      });
      send[std::size_t(q)].assign(reinterpret_cast<const char*>(place.data()),
                                  place.size() * sizeof(std::int64_t));
    }
    const std::vector<std::string> got = comm_.all_to_all(send);
    owned_.assign(grid.nodes(), 1);
    for (int q = 0; q < comm_.size(); ++q) {
      if (q == comm_.rank() || local[std::size_t(q)].empty()) continue;
      const auto* theirs = reinterpret_cast<const std::int64_t*>(got[std::size_t(q)].data());
      const std::size_t nt = got[std::size_t(q)].size() / sizeof(std::int64_t);
      const auto* ours = reinterpret_cast<const std::int64_t*>(send[std::size_t(q)].data());
      std::vector<std::int64_t> common;
      for (std::size_t a = 0, b = 0; a < local[std::size_t(q)].size() && b < nt;) {
        if (ours[a] < theirs[b])
          ++a;
        else if (theirs[b] < ours[a])
          ++b;
        else
          common.push_back(local[std::size_t(q)][a]), ++a, ++b;
      }
      if (common.empty()) continue;
      if (q < comm_.rank())
        for (auto node : common) owned_[std::size_t(node)] = 0;
      partners_.push_back(q);
      shared_.push_back(std::move(common));
    }
    // The union of the shared nodes, and each partner's list as positions in it.
    union_.clear();
    for (const auto& s : shared_) union_.insert(union_.end(), s.begin(), s.end());
    std::sort(union_.begin(), union_.end());
    union_.erase(std::unique(union_.begin(), union_.end()), union_.end());
    slot_.assign(shared_.size(), {});
    for (std::size_t k = 0; k < shared_.size(); ++k)
      for (auto node : shared_[k])
        slot_[k].push_back(
            std::uint32_t(std::lower_bound(union_.begin(), union_.end(), node) - union_.begin()));
    shared_nodes_ = double(union_.size());
  }

  /// Sums the shared nodes' mass (m), momentum (v), force (a) and remapped momentum (v_remap)
  /// (the `fields` bits kMass, kMomentum, kForce, kRemap of scatter.hpp: 1, 2, 4, 8) across the
  /// ranks that hold them, in rank order.
  void sum_shared(GridT& grid, int fields) {
    if (partners_.empty()) return;
    const int width =
        ((fields & 1) ? 1 : 0) +
        D * (((fields & 2) ? 1 : 0) + ((fields & 4) ? 1 : 0) + ((fields & 8) ? 1 : 0));
    auto pack = [&](std::int64_t node, double* out) {
      if (fields & 1) *out++ = grid.m[std::size_t(node)];
      for (int f = 1; f < 4; ++f)
        if (fields & (1 << f))
          for (int a = 0; a < D; ++a) *out++ = field(grid, f)[std::size_t(node)][a];
    };
    send_.resize(partners_.size()), recv_.resize(partners_.size());
    for (std::size_t k = 0; k < partners_.size(); ++k) {
      send_[k].resize(shared_[k].size() * std::size_t(width));
      recv_[k].resize(send_[k].size());
      for (std::size_t j = 0; j < shared_[k].size(); ++j)
        pack(shared_[k][j], &send_[k][j * std::size_t(width)]);
    }
    comm_.exchange(partners_, send_, recv_);
    // Every holder adds the holders' values in rank order, its own in its place.
    acc_.assign(union_.size() * std::size_t(width), 0.0);
    auto add = [&](std::size_t k, const std::vector<double>& values) {
      for (std::size_t j = 0; j < shared_[k].size(); ++j) {
        double* a = &acc_[slot_[k][j] * std::size_t(width)];
        for (int c = 0; c < width; ++c) a[c] += values[j * std::size_t(width) + std::size_t(c)];
      }
    };
    std::size_t k = 0;
    for (; k < partners_.size() && partners_[k] < comm_.rank(); ++k) add(k, recv_[k]);
    std::vector<double> own(static_cast<std::size_t>(width));
    for (std::size_t u = 0; u < union_.size(); ++u) {
      pack(union_[u], own.data());
      for (int c = 0; c < width; ++c)
        acc_[u * std::size_t(width) + std::size_t(c)] += own[std::size_t(c)];
    }
    for (; k < partners_.size(); ++k) add(k, recv_[k]);
    for (std::size_t u = 0; u < union_.size(); ++u) {
      const double* a = &acc_[u * std::size_t(width)];
      const std::size_t node = std::size_t(union_[u]);
      if (fields & 1) grid.m[node] = *a++;
      for (int f = 1; f < 4; ++f)
        if (fields & (1 << f))
          for (int c = 0; c < D; ++c) field(grid, f)[node][c] = *a++;
    }
  }

  /// The largest of the holders' marks at every shared node (the rigid bodies' marks, which a
  /// rank sets only from its own rigid particles; where two bodies mark one node across a cut
  /// the higher mark wins, as the later one does in one process).
  void max_shared(std::vector<std::uint8_t>& marks) {
    if (partners_.empty()) return;
    send_.resize(partners_.size()), recv_.resize(partners_.size());
    for (std::size_t k = 0; k < partners_.size(); ++k) {
      send_[k].resize(shared_[k].size());
      recv_[k].resize(shared_[k].size());
      for (std::size_t j = 0; j < shared_[k].size(); ++j)
        send_[k][j] = marks[std::size_t(shared_[k][j])];
    }
    comm_.exchange(partners_, send_, recv_);
    for (std::size_t k = 0; k < partners_.size(); ++k)
      for (std::size_t j = 0; j < shared_[k].size(); ++j) {
        std::uint8_t& m = marks[std::size_t(shared_[k][j])];
        m = std::max(m, std::uint8_t(recv_[k][j]));
      }
  }

  /// Whether this rank counts node `node` in node sums (it is the lowest rank holding it).
  bool owns(std::int64_t node) const { return owned_.empty() || owned_[std::size_t(node)] != 0; }
  /// All ranks' particles after the last migration.
  std::size_t total_particles() const { return total_; }
  /// The slab axis (rank r holds the cells [cut_[r], cut_[r + 1]) along it).
  int axis() const { return axis_; }
  /// Nodes this rank shares with others (after the last sort); particles it sent away so far.
  double shared_nodes() const { return shared_nodes_; }
  double migrated() const { return migrated_; }

 private:
  int owner(int c) const {
    return int(std::upper_bound(cut_.begin(), cut_.end(), c) - cut_.begin()) - 1;
  }
  static std::vector<Vec<D>>& field(GridT& g, int f) {
    return f == 1 ? g.v : f == 2 ? g.a : g.v_remap;
  }
  /// f(k, place) for the global nodes k of the box [lo, hi], axis 0 fastest.
  template <class F>
  static void each_node(const IVec<D>& lo, const IVec<D>& hi, F&& f) {
    IVec<D> k = lo;
    std::int64_t at = 0;
    while (true) {
      f(k, at++);
      int a = 0;
      while (a < D && ++k[a] > hi[a]) k[a] = lo[a], ++a;
      if (a == D) return;
    }
  }

  const Comm& comm_;
  int axis_ = D - 1;
  std::vector<int> cut_;
  std::size_t total_ = 0;
  std::vector<int> partners_;                      ///< ranks sharing nodes, ascending
  std::vector<std::vector<std::int64_t>> shared_;  ///< by partner: the shared nodes
  std::vector<std::int64_t> union_;                ///< all shared nodes, ascending
  std::vector<std::vector<std::uint32_t>> slot_;   ///< by partner: positions in union_
  std::vector<std::uint8_t> owned_;
  std::vector<std::vector<double>> send_, recv_;
  std::vector<double> acc_;
  double shared_nodes_ = 0, migrated_ = 0;
};

}  // namespace mpm
