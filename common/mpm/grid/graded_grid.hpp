#pragma once
/// The mesh-grading background grid (004, sections 3.1-3.2). Level 1 covers the domain with
/// cells of size h1 (grid.cell_size); a level-l box (grid.levels) replaces the level-(l-1)
/// cells it covers by cells of size h1 / 2^(l-1). Boxes are aligned to the coarser lattice and
/// nested, and neighbouring cells differ by at most one level (faces, edges and corners), so a
/// coarse cell on a level interface carries at most the mid-edge and mid-face nodes of
/// transition_shape.hpp (hanging nodes; they are ordinary degrees of freedom here, shared with
/// the finer cells whose corners they are).
///
/// One node list holds every level. Cells (the solver's sort keys) are numbered level-1 cell
/// by level-1 cell along the slab axis (the domain's longest), the leaves inside each level-1
/// cell in depth-first order, so the keys of one slab layer are contiguous and two cells in
/// layers that are not adjacent never share a node: the coloured, lock-free scatter of
/// binning.hpp works unchanged. A point is located by searching the levels from fine to coarse.
///
/// As UniformGrid, cells and nodes exist only in a window of level-1 cells around the particles
/// (the level boxes clipped to it); fit() rebuilds the grid when the particles leave the window
/// or it has grown much larger than they need. Level boxes may follow a body
/// (LevelSpec::follow): the solver reports the body's mass centre every step and the grid is
/// rebuilt at the next sort when the boxes moved by a whole level-1 cell.
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "mpm/core/state_values.hpp"
#include "mpm/core/types.hpp"
#include "mpm/grid/grid.hpp"
#include "mpm/grid/lattice.hpp"
#include "mpm/grid/shape.hpp"
#include "mpm/grid/transition_shape.hpp"
#include "mpm/scene/scene.hpp"
#include "mpm/stream/grid_record.hpp"

namespace mpm {

template <int D>
class GradedGrid {
 public:
  static constexpr int kDim = D;
  static constexpr int kMaxNodes = kTransitionNodes<D>;
  static constexpr bool kFixedNodes = false;
  static constexpr bool kGraded = true;

  /// Builds the grid of a scene's level boxes (scene.grid.levels) on its lattice. Throws
  /// InputError naming the level box (file, line, key) when boxes are not aligned to the
  /// coarser lattice, not nested, closer than one coarser cell to the edge of the coarser
  /// region (so that cells would differ by two levels), or form a concave corner on which a
  /// transition cell would get negative shape functions.
  GradedGrid(const Lattice& lattice, const Scene& scene);

  /// Fits the window to the level-1 cells of n particles (with `margin` cells around them;
  /// a rebuild leaves 3), and rebuilds the grid when the window or the followed boxes moved.
  void fit(const Vec<D>* x, std::size_t n, int margin = 1);

  // Location ---------------------------------------------------------------------------------
  /// Cell key and position in the cell (fractions of its size, in [0,1)) of a point inside
  /// the domain, searching the levels from the finest to the coarsest (004, section 3.2).
  /// The search descends from the level-1 cell through the refined cells (a 2^D-tree), which
  /// visits the levels from coarse to fine but finds the finest cell holding the point, as
  /// searching the levels from fine to coarse would. Halving the position is exact, so a point
  /// on an interface goes where the half-open cells [lo, hi) of every level put it.
  [[gnu::always_inline]] void locate(const Vec<D>& x, std::int64_t& key, Vec<D>& xi) const {
    Vec<D> r = (x - origin_) * inv_h1_;
    std::int64_t idx = 0;
    for (int a = 0; a < D; ++a) {
      const double f = std::floor(r[a]);
      const std::int64_t c = std::int64_t(f) - wlo_[a];
      if (c < 0 || c >= wn_[a]) {
        key = -1;
        xi.setZero();
        return;
      }
      idx += c * stride1_[a];
      r[a] -= f;
    }
    std::int32_t v = root_[idx];
    while (v < 0) {  // a refined cell: down to the child holding the point
      int bits = 0;
      for (int a = 0; a < D; ++a) {
        r[a] *= 2.0;
        if (r[a] >= 1.0) r[a] -= 1.0, bits |= 1 << a;
      }
      v = tree_[(std::size_t(-1 - v) << D) + bits];
    }
    key = v;
    xi = r;
  }
  /// The kernels' fast path for a particle of a bin: true when x lies in cell `key`, with xi
  /// set to exactly what locate() would give (r 2^(l-1) minus the cell's integer index is the
  /// fraction locate's halvings leave, and both are exact), without descending the tree.
  [[gnu::always_inline]] bool in_cell(const Vec<D>& x, std::int64_t key, Vec<D>& xi) const {
    const Vec<D> r = (x - origin_) * inv_h1_;
    xi = r * scale_[info_[key] >> kLevelShift] - cell_lo_[key];
    for (int a = 0; a < D; ++a)
      if (!(xi[a] >= 0.0 && xi[a] < 1.0)) return false;
    return true;
  }
  /// Where a point is (the grid is all window); key and xi are set when it is inside.
  Where where(const Vec<D>& x, std::int64_t& key, Vec<D>& xi) const {
    locate(x, key, xi);
    if (key >= 0) return Where::Window;
    for (int a = 0; a < D; ++a) {
      const double c = std::floor((x[a] - origin_[a]) * inv_h1_);
      if (!(c >= 0 && c < cells1_[a])) return Where::OutsideDomain;
    }
    return Where::OutsideWindow;
  }
  /// Nodes of a cell: its corners in bit order, then its present optional nodes in increasing
  /// number (transition_shape.hpp); returns their count (2^D to kMaxNodes).
  [[gnu::always_inline]] int cell_nodes(std::int64_t key, std::int64_t* nodes) const {
    const Cell& c = cells_[key];
    for (int k = 0; k < kCorners<D>; ++k) nodes[k] = c.corner[k];
    if (c.mask == 0) return kCorners<D>;
    const int n = std::popcount(c.mask);
    for (int j = 0; j < n; ++j) nodes[kCorners<D> + j] = optional_[c.opt + j];
    return kCorners<D> + n;
  }
  /// Shape functions and gradients (1/m) at position xi of a cell, in cell_nodes order.
  [[gnu::always_inline]] void shape(std::int64_t key, const Vec<D>& xi, double* N,
                                    Vec<D>* G) const {
    const std::uint32_t info = info_[key], mask = info & kMaskBits;
    const double inv_h = inv_h_[info >> kLevelShift];
    if (mask == 0)
      shape_functions<D>(xi, inv_h, N, G);
    else
      transition_shape<D>(mask, xi, inv_h, N, G);
  }
  [[gnu::always_inline]] void values(std::int64_t key, const Vec<D>& xi, double* N) const {
    const std::uint32_t mask = info_[key] & kMaskBits;
    if (mask == 0) {
      // Trilinear weights as products of the axis factors (the regular cell's fast path).
      const double w[3][2] = {{1.0 - xi[0], xi[0]},
                              {1.0 - xi[1], xi[1]},
                              {D == 3 ? 1.0 - xi[D - 1] : 1.0, D == 3 ? xi[D - 1] : 0.0}};
      for (int c = 0; c < kCorners<D>; ++c)
        N[c] = w[0][c & 1] * w[1][(c >> 1) & 1] * (D == 3 ? w[2][(c >> 2) & 1] : 1.0);
      return;
    } else
      transition_shape<D>(mask, xi, 1.0, N, nullptr);
  }
  std::size_t key_count() const { return cells_.size(); }
  /// Slab layer of a key: the position of its level-1 ancestor along the slab axis.
  int layer(std::int64_t key) const { return cells_[key].layer; }
  int layers() const { return wn_[slab_]; }
  int slab_axis() const { return slab_; }
  /// Size of a cell (m): its level's. The length of the bulk viscosity of the particles in it
  /// (a shock is spread over the cells it crosses, so its viscosity scales with them).
  double cell_size(std::int64_t key) const { return level_[cells_[key].level].h; }
  /// The finest cell's size (m): the length of the time step, which must hold for the finest
  /// cells (004, section 3.4).
  double min_cell_size() const { return level_[levels_].h; }
  /// The size of the largest cell a node's shape function spans (m): its level's cells inside
  /// a level, the coarser cells' on a level interface (hanging nodes included). What a
  /// distance measured at the node compares with, e.g. contact's gap.
  double node_cell_size(std::int64_t n) const { return level_[node_level_[n]].h; }

  // Levels -----------------------------------------------------------------------------------
  int levels() const { return levels_; }
  /// Cell size of level l (1 <= l <= levels()), m.
  double level_h(int l) const { return level_[l].h; }
  int cell_level(std::int64_t key) const { return cells_[key].level; }
  std::uint32_t cell_mask(std::int64_t key) const { return cells_[key].mask; }
  /// The finest level whose region contains x (1 when x lies in no box; 0 outside the window).
  int level_at(const Vec<D>& x) const {
    std::int64_t key;
    Vec<D> xi;
    locate(x, key, xi);
    return key < 0 ? 0 : cells_[key].level;
  }
  /// True when x lies in a level box of a level above `level` (the boxes of level + 1 contain
  /// every finer one): a particle of that level there is coarser than its cell.
  bool in_finer(const Vec<D>& x, int level) const {
    if (level >= levels_) return false;
    for (const Box& b : boxes_) {
      if (b.level != level + 1) continue;
      bool in = true;
      for (int a = 0; a < D && in; ++a) in = x[a] >= b.xmin[a] && x[a] < b.xmax[a];
      if (in) return true;
    }
    return false;
  }
  /// Lower corner (m) and size (m) of a cell.
  Vec<D> cell_origin(std::int64_t key) const { return node_position(cells_[key].corner[0]); }
  double cell_h(std::int64_t key) const { return level_[cells_[key].level].h; }
  /// Position of a node, m.
  Vec<D> node_position(std::int64_t n) const {
    return origin_ + h_fine_ * node_ijk_[n].template cast<double>();
  }
  /// True for a node that is an optional node of some cell (a hanging node).
  bool hanging(std::int64_t n) const { return hanging_[n] != 0; }
  /// Counts of the current build: cells per level, transition cells, hanging nodes.
  std::vector<std::size_t> cells_per_level() const;
  std::size_t transition_cells() const;
  std::size_t hanging_nodes() const;
  /// The grid over the whole domain (whatever the window) as written to a GRID record.
  GridMesh mesh(std::int64_t step, double time) const;
  /// Incremented when the level boxes move (the run writes a new GRID record then).
  long revision() const { return revision_; }
  /// Builds so far (window changes and moves).
  long builds() const { return builds_; }

  // Following a body -------------------------------------------------------------------------
  /// The body the level boxes follow, -1 when they are fixed.
  int followed_body() const { return follow_body_; }
  /// Tells the grid where the followed body's mass centre is now (the first call sets the
  /// reference). Returns true when the boxes move by whole level-1 cells, which takes effect
  /// at the next fit; a move that would break the nesting rules at the domain's faces is not
  /// made (the boxes stay).
  bool follow(const Vec<D>& centre);
  /// Corners of the grid domain, m.
  Vec<D> domain_min() const { return origin_; }
  Vec<D> domain_max() const { return origin_ + h1_ * cells1_.template cast<double>(); }
  /// Displacement of the boxes from their scene position, m.
  Vec<D> box_offset() const { return h1_ * offset_.template cast<double>(); }

  // Checkpoints ------------------------------------------------------------------------------
  /// What the grid carries from step to step besides the particles: the window, the boxes'
  /// offset (built and pending), the followed body's first centre, the revision.
  void save_state(StateValues& s) const;
  /// Restores save_state's values and builds the grid they describe, before the first sort, so
  /// that a continued run sorts and steps as the uninterrupted one.
  void restore_state(const StateValues& s);

  // Node data (structure of arrays), as UniformGrid -----------------------------------------
  std::size_t nodes() const { return m.size(); }
  std::vector<double> m;            ///< nodal mass, kg
  std::vector<Vec<D>> v;            ///< momentum, then velocity
  std::vector<Vec<D>> a;            ///< force, then acceleration
  std::vector<Vec<D>> v_remap;      ///< MUSL: remapped momentum, then velocity
  std::vector<std::uint8_t> rigid;  ///< 1 + index of the rigid body touching the node, or 0
  void clear(bool remap, bool rigid_bodies = false);
  void clear_remap();

  // Boundary conditions ----------------------------------------------------------------------
  struct FaceNode {
    std::int64_t node;
    int face;  ///< 2 * axis + (0 for min, 1 for max)
  };
  const std::vector<FaceNode>& fixed_nodes() const { return fixed_; }
  const std::vector<FaceNode>& slip_nodes() const { return slip_; }
  const BoundarySpec& boundary() const { return boundary_; }

 private:
  /// A level box in cells of its level (hi exclusive), at its scene position.
  struct Box {
    int level = 2;
    IVec<D> lo, hi;
    Vec<D> xmin, xmax;  ///< its current extent, m
    SourceLoc loc;
    int index = 0;  ///< position in scene.grid.levels
  };
  /// One level's region: a dense array over its bounding box (cells of the level) holding
  /// the cell key of each leaf, kNotInLevel outside the level's boxes, kRefined where a finer
  /// level takes over.
  struct Level {
    double h = 0, inv_h = 0, scale = 1;  ///< cell size, 1/h, 2^(l-1)
    IVec<D> lo = IVec<D>::Zero(), n = IVec<D>::Zero();
    std::array<std::int64_t, D> stride{};
    std::vector<std::int32_t> cell;
    /// Position of cell c (in cells of the level) in `cell`.
    std::int64_t index(const IVec<D>& c) const {
      std::int64_t idx = 0;
      for (int a = 0; a < D; ++a) idx += std::int64_t(c[a] - lo[a]) * stride[a];
      return idx;
    }
    /// True when cell c lies in the region's bounding box.
    bool holds(const IVec<D>& c) const {
      for (int a = 0; a < D; ++a)
        if (c[a] < lo[a] || c[a] >= lo[a] + n[a]) return false;
      return true;
    }
    /// Lays the region over the cells [lo, hi), every one kNotInLevel.
    void layout(const IVec<D>& lo_cell, const IVec<D>& hi_cell) {
      lo = lo_cell;
      n = hi_cell - lo_cell;
      std::int64_t s = 1;
      for (int a = 0; a < D; ++a) stride[a] = s, s *= n[a];
      cell.assign(std::size_t(s), kNotInLevel);
    }
  };
  static constexpr std::int32_t kNotInLevel = -1, kRefined = -2;
  struct Cell {
    std::array<std::int32_t, kCorners<D>> corner;
    std::uint32_t mask = 0;  ///< optional nodes present
    std::uint32_t opt = 0;   ///< first entry in optional_
    std::int32_t layer = 0;
    std::uint8_t level = 1;
  };

  /// Builds cells and nodes in the window [wlo_, wlo_ + wn_). With `validate` (the whole
  /// domain), checks the boxes and throws InputError; else returns false when clipping the
  /// boxes to the window would give a transition cell with negative shape functions.
  bool build(bool validate);
  // The stages of build(), in order:
  /// The slab axis and strides of the window; the boxes' extents at the current offset.
  void place_boxes();
  /// Level 1's region is the window, level l's the union of its boxes clipped to it. With
  /// `validate`, a level without boxes below a finer level's box fails.
  void build_regions(bool validate);
  /// Nesting and 2:1 balance of the boxes (on the whole domain); throws InputError.
  void check_nesting() const;
  /// Marks the level-(l-1) cells that level-l cells cover as refined (no leaves).
  void mark_refined();
  /// Numbers the leaves (the cell keys) and builds locate's tree; returns each leaf's position
  /// in cells of its level.
  std::vector<IVec<D>> number_cells();
  /// Numbers the corner nodes of the leaves; returns the node arrays of the levels (node_slot).
  std::vector<Level> number_nodes(const std::vector<IVec<D>>& cpos);
  /// Finds the optional nodes of the cells (hanging nodes). Returns false when, without
  /// `validate`, a transition cell would get negative shape functions (fail_concave with it).
  bool add_optional_nodes(const std::vector<IVec<D>>& cpos, std::vector<Level>& nodes_of,
                          bool validate);
  /// The nodes on the constrained domain faces.
  void set_boundary_nodes();
  /// The box's cells at the current offset, clipped to the window; false when that is empty.
  bool clipped(const Box& b, IVec<D>& lo, IVec<D>& hi) const;
  /// The node slot of a point P (in finest cells) in the node arrays of the levels: at the
  /// coarsest level whose lattice holds P; nullptr when that level's array does not hold it.
  std::int32_t* node_slot(std::vector<Level>& nodes_of, const IVec<D>& P) const;
  /// Fails at the finer box nearest to a transition cell (at position pos in cells of its
  /// level) whose shape functions would be negative: boxes meeting it on two sides.
  [[noreturn]] void fail_concave(const Cell& cell, const IVec<D>& pos) const;
  [[noreturn]] void fail(const Box& b, const std::string& key, const std::string& message) const;
  std::string mm(const Vec<D>& x) const;

  Lattice lattice_;
  BoundarySpec boundary_;
  Vec<D> origin_;
  double h1_ = 0, inv_h1_ = 0, h_fine_ = 0;
  IVec<D> cells1_;
  int levels_ = 1;
  int slab_ = D - 1;
  std::vector<Box> boxes_;
  int follow_body_ = -1;
  bool have_centre0_ = false;
  Vec<D> centre0_ = Vec<D>::Zero();
  IVec<D> offset_ = IVec<D>::Zero(), built_offset_ = IVec<D>::Zero();
  IVec<D> wlo_ = IVec<D>::Zero(), wn_ = IVec<D>::Zero();  ///< window, level-1 cells
  long revision_ = 0, builds_ = 0;

  std::vector<Level> level_;  ///< index 1..levels_
  std::vector<Cell> cells_;
  // The hot path: locate's 2^D-tree (a level-1 cell or a child slot holds a leaf's key, or
  // -1 - t for a refined cell whose children are tree_[t 2^D ...]), and per key the mask and
  // the level in one word.
  static constexpr std::uint32_t kMaskBits = (1u << 24) - 1;
  static constexpr int kLevelShift = 24;
  std::array<std::int64_t, D> stride1_{};
  std::vector<std::int32_t> root_, tree_;
  std::vector<std::uint32_t> info_;
  std::array<double, 16> inv_h_{};
  std::array<double, 16> scale_{};  ///< 2^(l-1) by level
  std::vector<Vec<D>> cell_lo_;     ///< per key: the cell's index in its level's cells, as doubles
  std::vector<std::int32_t> optional_;
  std::vector<IVec<D>> node_ijk_;  ///< node positions in finest cells from the origin
  std::vector<std::uint8_t> hanging_;
  std::vector<std::uint8_t> node_level_;  ///< level of the coarsest cell using the node
  std::vector<FaceNode> fixed_, slip_;
};

}  // namespace mpm
