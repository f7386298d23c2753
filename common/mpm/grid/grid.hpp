#pragma once
/// The background grid. The lattice spans the whole domain, but node arrays exist only in a
/// window around the particles, refitted whenever particles are re-sorted (000, section 4.3:
/// the grid follows the material). Boundary conditions sit on the domain's faces and are
/// applied to the window's nodes that lie on those faces, so the window changes nothing of
/// the result: a node outside the window has no mass and no influence.
#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <vector>

#include "mpm/core/types.hpp"
#include "mpm/grid/lattice.hpp"
#include "mpm/grid/shape.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm {

/// Where a point lies relative to a grid.
enum class Where : std::uint8_t { Window, OutsideWindow, OutsideDomain };

/// The bounding box [lo, hi] of the lattice cells (side 1 / inv_h, counted from origin) that
/// hold the points x[0, n): a parallel min/max, the first half of every grid's fit(). lo and
/// hi are 0 when n = 0; points must lie inside the `cells` of the domain.
template <int D>
void cell_bounds(const Vec<D>* x, std::size_t n, const Vec<D>& origin, double inv_h,
                 const IVec<D>& cells, IVec<D>& lo, IVec<D>& hi) {
  lo = cells, hi = IVec<D>::Constant(-1);
#pragma omp parallel
  {
    IVec<D> tlo = cells, thi = IVec<D>::Constant(-1);
#pragma omp for schedule(static) nowait
    for (std::size_t i = 0; i < n; ++i)
      for (int a = 0; a < D; ++a) {
        const int c = int(std::floor((x[i][a] - origin[a]) * inv_h));
        tlo[a] = std::min(tlo[a], c);
        thi[a] = std::max(thi[a], c);
      }
#pragma omp critical
    {
      lo = lo.cwiseMin(tlo);
      hi = hi.cwiseMax(thi);
    }
  }
  if (n == 0) lo.setZero(), hi.setZero();
}

/// The node data every uniform grid holds (structure of arrays) and its constrained nodes.
/// Scatter kernels accumulate momentum into v, force into a and remapped momentum into
/// v_remap; the grid kernels then divide by the mass, so after them these hold velocity (m/s)
/// and acceleration (m/s^2).
template <int D>
class GridNodes {
 public:
  explicit GridNodes(const BoundarySpec& boundary) : boundary_(boundary) {}

  std::vector<double> m;            ///< nodal mass, kg
  std::vector<Vec<D>> v;            ///< momentum, then velocity
  std::vector<Vec<D>> a;            ///< force, then acceleration
  std::vector<Vec<D>> v_remap;      ///< MUSL: remapped momentum, then velocity
  std::vector<std::uint8_t> rigid;  ///< 1 + index of the rigid body touching the node, or 0
  std::size_t nodes() const { return m.size(); }

  /// Clears m, v and a (v_remap when `remap`, rigid when `rigid_bodies`, sizing those two to
  /// m). A node without mass holds no momentum, force or remapped momentum (the grid kernels
  /// keep it so), so after the first clear following a refit only the nodes that carried mass
  /// are cleared: empty nodes cost one read.
  void clear(bool remap, bool rigid_bodies = false) {
    const std::int64_t n = std::int64_t(m.size());
    const bool full = !clean_ || (remap && v_remap.size() != m.size());
    if (remap && v_remap.size() != m.size()) v_remap.resize(m.size());
    if (rigid_bodies && rigid.size() != m.size()) rigid.resize(m.size());
#pragma omp parallel for schedule(static)
    for (std::int64_t i = 0; i < n; ++i) {
      if (full || m[i] != 0) {
        m[i] = 0;
        v[i].setZero();
        a[i].setZero();
        if (remap) v_remap[i].setZero();
      }
      if (rigid_bodies) rigid[i] = 0;
    }
    clean_ = true;
  }

  /// A node on a constrained domain face; face = 2 * axis + (0 for min, 1 for max).
  struct FaceNode {
    std::int64_t node;
    int face;
  };
  /// Nodes on fixed faces (every velocity component held at zero).
  const std::vector<FaceNode>& fixed_nodes() const {
    return fixed_;
  }
  /// Nodes on slip faces (the normal component held at zero).
  const std::vector<FaceNode>& slip_nodes() const {
    return slip_;
  }
  const BoundarySpec& boundary() const {
    return boundary_;
  }
  /// A ghost node (outside the domain, beyond a constrained face: B-spline grids) and its
  /// mirror image in the face's node plane. The face is a plane of symmetry, as if the body's
  /// mirror image lay beyond it: the ghost's mass, momentum and force fold into the mirror node,
  /// reflected, and after the update the ghost takes the mirror's velocity, reflected. A slip
  /// face reflects the normal component, a fixed face every component.
  struct GhostNode {
    std::int64_t node, mirror;  ///< mirror: -1 when outside the node arrays
    int face;
    bool fixed;
  };
  const std::vector<GhostNode>& ghost_nodes() const {
    return ghosts_;
  }
  static Vec<D> reflect(const GhostNode& g, Vec<D> v) {
    if (g.fixed) return -v;
    v[g.face / 2] = -v[g.face / 2];
    return v;
  }

 protected:
  /// Sizes the node arrays to n nodes whose meaning has changed (the next clear is full).
  void resize_nodes(std::size_t n) {
    clean_ = false;
    m.resize(n);
    v.resize(n);
    a.resize(n);
    if (!v_remap.empty()) v_remap.resize(n);
    if (!rigid.empty()) rigid.resize(n);
  }
  /// Lists the nodes on constrained domain faces (a domain of `cells`) among the nodes of the
  /// box whose lowest node is the global node `lo` and which has `count` nodes along each axis;
  /// index(k) gives the node of the box's local node k, or -1 when there is none. Faces in
  /// order, then the other axes' nodes with the lower axis fastest.
  /// With `ghost` layers of nodes outside the domain (a lattice widened by that many cells on
  /// every side: the B-spline grid), a face is the node plane `ghost` in from the lattice's
  /// edge, and the planes beyond it are ghost nodes with their mirrors (GhostNode).
  template <class Index>
  void collect_face_nodes(const IVec<D>& cells, const IVec<D>& lo, const IVec<D>& count,
                          Index&& index, int ghost = 0) {
    fixed_.clear();
    slip_.clear();
    ghosts_.clear();
    for (int face = 0; face < 2 * D; ++face) {
      const BoundaryType type = boundary_.face[face];
      if (type == BoundaryType::Free) continue;
      const int axis = face / 2;
      const auto plane = [&](int g) { return ((face % 2 == 0) ? g : cells[axis] - g) - lo[axis]; };
      const bool fixed = type == BoundaryType::Fixed;
      collect_plane(axis, plane(ghost), count, index, [&](std::int64_t node, const IVec<D>&) {
        (fixed ? fixed_ : slip_).push_back({node, face});
      });
      for (int g = 0; g < ghost; ++g) {
        const int mirror = plane(2 * ghost - g);
        collect_plane(axis, plane(g), count, index, [&](std::int64_t node, IVec<D> k) {
          k[axis] = mirror;
          const bool inside = mirror >= 0 && mirror < count[axis];
          ghosts_.push_back({node, inside ? std::int64_t(index(k)) : -1, face, fixed});
        });
      }
    }
  }
  /// add(node, k) for the nodes k of the local node plane `local` normal to `axis`.
  template <class Index, class Add>
  static void collect_plane(int axis, int local, const IVec<D>& count, Index& index, Add&& add) {
    if (local < 0 || local >= count[axis]) return;
    IVec<D> k = IVec<D>::Zero();
    k[axis] = local;
    const int other0 = axis == 0 ? 1 : 0;
    const int other1 = D == 3 ? (axis == 2 ? 1 : 2) : -1;
    const int n0 = count[other0], n1 = other1 >= 0 ? count[other1] : 1;
    for (int j = 0; j < n1; ++j)
      for (int i = 0; i < n0; ++i) {
        k[other0] = i;
        if (other1 >= 0) k[other1] = j;
        const std::int64_t node = index(k);
        if (node >= 0) add(node, k);
      }
  }

  BoundarySpec boundary_;
  bool clean_ = false;  ///< nodes without mass hold zeros everywhere

 private:
  std::vector<FaceNode> fixed_, slip_;
  std::vector<GhostNode> ghosts_;
};

/// The lattice geometry the uniform grids share: cubic (square) cells of side h counted from the
/// domain's origin, the domain's cell counts, where a point lies, and the box of cells a set
/// of particles needs.
template <int D>
class CellLattice {
 public:
  explicit CellLattice(const Lattice& lattice);

  double h() const { return h_; }
  double inv_h() const { return inv_h_; }
  const Vec<D>& origin() const { return origin_; }
  /// Cells of the domain along each axis.
  const IVec<D>& cells() const { return cells_; }
  /// Global cell of a position and the position within it (fractions of h in [0,1)).
  void locate(const Vec<D>& x, IVec<D>& cell, Vec<D>& xi) const {
    const Vec<D> r = (x - origin_) * inv_h_;
    for (int a = 0; a < D; ++a) {
      const double f = std::floor(r[a]);
      cell[a] = int(f);
      xi[a] = r[a] - f;
    }
  }
  /// Whether x lies in the global cell c (its indices as doubles), and its local coordinates
  /// there. locate's r = (x - origin) / h has floor(r) = c exactly when c <= r < c + 1, and then
  /// its xi = r - floor(r) is r - c: the same answer and the same xi as locate, without the
  /// floor and the conversion (false for NaN). (r is compared, so it is rounded before r - c:
  /// no fused multiply-add there.) The trilinear kernels write it out in plain doubles for
  /// their vector loops (ExplicitSolver::cell_lanes).
  [[gnu::always_inline]] bool in_cell(const double* c, const Vec<D>& x, Vec<D>& xi) const {
    bool in = true;
    for (int a = 0; a < D; ++a) {
      const double r = (x[a] - origin_[a]) * inv_h_;
      in = in & (r >= c[a]) & (r < c[a] + 1.0);
      xi[a] = r - c[a];
    }
    return in;
  }
  /// True when a global cell lies inside the domain.
  bool in_domain(const IVec<D>& cell) const {
    for (int a = 0; a < D; ++a)
      if (cell[a] < 0 || cell[a] >= cells_[a]) return false;
    return true;
  }
  double cell_size(std::int64_t) const { return h_; }
  double min_cell_size() const { return h_; }
  double node_cell_size(std::int64_t) const { return h_; }
  /// Shape functions and gradients (1/m) at local coordinates xi of a cell.
  void shape(std::int64_t, const Vec<D>& xi, double* N, Vec<D>* G) const {
    shape_functions<D>(xi, inv_h_, N, G);
  }
  void values(std::int64_t, const Vec<D>& xi, double* N) const { shape_values<D>(xi, N); }
  /// x_i - x_p of a cell's corners, in cells (APIC's affine momentum, p2g).
  void offsets(std::int64_t, const Vec<D>& xi, Vec<D>* d) const {
    for (int c = 0; c < kCorners<D>; ++c)
      for (int a = 0; a < D; ++a) d[c][a] = double((c >> a) & 1) - xi[a];
  }
  /// APIC's C_p = sum_i v_i W_i^T: W = B-to-C weights, here the gradients (for multilinear
  /// weights D_p^-1 N (x_i - x_p) = grad N: Jiang et al. 2015).
  void affine_weights(std::int64_t, const Vec<D>&, const double*, const Vec<D>* G,
                      Vec<D>* W) const {
    for (int c = 0; c < kCorners<D>; ++c) W[c] = G[c];
  }

 protected:
  /// The cells [lo, hi] of n particles widened by `margin` cells, clamped to the domain; returns
  /// the slab axis, the longest extent (ties go to the highest axis).
  int particle_box(const Vec<D>* x, std::size_t n, int margin, IVec<D>& lo, IVec<D>& hi) const;

  Vec<D> origin_;
  double h_, inv_h_;
  IVec<D> cells_;  ///< domain cells per axis
};

/// What the solvers' kernels need of a grid: UniformGrid, SparseGrid and GradedGrid.
template <class G>
concept Grid = requires(G& g, const G& cg, const Vec<G::kDim>* xs, std::size_t n,
                        const Vec<G::kDim>& x, std::int64_t& key, Vec<G::kDim>& xi,
                        std::int64_t* nodes, double* N, Vec<G::kDim>* dN) {
  // 2D or 3D; nodes of a cell at most; every cell has kMaxNodes; levels (particles split).
  requires G::kDim == 2 || G::kDim == 3;
  { G::kMaxNodes } -> std::convertible_to<int>;
  { G::kFixedNodes } -> std::convertible_to<bool>;
  { G::kGraded } -> std::convertible_to<bool>;
  // The window (and levels) for n particles at xs.
  g.fit(xs, n);
  // Cell key and local coordinates of x (locate: x known to be in the window); a cell's
  // nodes (returns their count), shape functions and gradients (1/m); keys in
  // [0, key_count()), in slab layers for the coloured scatter; cell sizes, m.
  { cg.where(x, key, xi) } -> std::same_as<Where>;
  cg.locate(x, key, xi);
  { cg.cell_nodes(key, nodes) } -> std::same_as<int>;
  cg.shape(key, xi, N, dN);
  cg.values(key, xi, N);
  { cg.key_count() } -> std::same_as<std::size_t>;
  { cg.layer(key) } -> std::same_as<int>;
  { cg.layers() } -> std::same_as<int>;
  { cg.cell_size(key) } -> std::same_as<double>;
  { cg.min_cell_size() } -> std::same_as<double>;
  { cg.node_cell_size(key) } -> std::same_as<double>;
  // Node data (GridNodes), cleared for a step, and the nodes on constrained domain faces.
  { cg.nodes() } -> std::same_as<std::size_t>;
  { g.m } -> std::same_as<std::vector<double>&>;
  { g.v } -> std::same_as<std::vector<Vec<G::kDim>>&>;
  { g.a } -> std::same_as<std::vector<Vec<G::kDim>>&>;
  { g.v_remap } -> std::same_as<std::vector<Vec<G::kDim>>&>;
  { g.rigid } -> std::same_as<std::vector<std::uint8_t>&>;
  g.clear(true, true);
  { cg.fixed_nodes().front().node } -> std::convertible_to<std::int64_t>;
  { cg.slip_nodes().front().face } -> std::convertible_to<int>;
};

template <int D>
class UniformGrid : public CellLattice<D>, public GridNodes<D> {
  using Base = CellLattice<D>;

 protected:
  using Base::cells_;

 public:
  using Base::locate;
  using GridNodes<D>::m;
  static constexpr int kDim = D;
  static constexpr int kMaxNodes = kCorners<D>;
  static constexpr bool kFixedNodes = true;
  static constexpr bool kGraded = false;  ///< no levels, no particle splitting

  /// `ghost`: layers of cells the lattice has outside the domain on every side (0; the
  /// B-spline grid builds on a lattice widened by 1), so that the domain faces lie `ghost`
  /// nodes in.
  UniformGrid(const Lattice& lattice, const BoundarySpec& boundary, int ghost = 0);

  /// Fits the window to the cells of n particles (their bounding box widened by `margin`
  /// cells, clamped to the domain), chooses the slab axis (the longest), and sizes the node
  /// arrays. Particles must be inside the domain.
  void fit(const Vec<D>* x, std::size_t n, int margin = 1);

  // Geometry (locate, in_domain, shape, values, cell sizes: CellLattice) -------------------
  const Lattice& lattice() const { return lattice_; }
  /// Cell key and local coordinates of a point known to be inside the window.
  void locate(const Vec<D>& x, std::int64_t& key, Vec<D>& xi) const {
    IVec<D> cell;
    locate(x, cell, xi);
    key = this->key(cell);
  }
  /// Where a point is; key and xi are set when it is in the window.
  Where where(const Vec<D>& x, std::int64_t& key, Vec<D>& xi) const {
    IVec<D> cell;
    locate(x, cell, xi);
    if (!this->in_domain(cell)) return Where::OutsideDomain;
    if (!in_window(cell)) return Where::OutsideWindow;
    key = this->key(cell);
    return Where::Window;
  }
  /// Nodes of a cell (its corners); returns their number.
  int cell_nodes(std::int64_t key, std::int64_t* nodes) const {
    for (int c = 0; c < kMaxNodes; ++c) nodes[c] = key + corner_[c];
    return kMaxNodes;
  }
  std::size_t key_count() const { return m.size(); }
  /// True when a global cell lies inside the window.
  bool in_window(const IVec<D>& cell) const {
    for (int a = 0; a < D; ++a)
      if (cell[a] < lo_[a] || cell[a] > hi_[a]) return false;
    return true;
  }
  /// Index of the lower corner node of a window cell; also the cell's sort key.
  std::int64_t key(const IVec<D>& cell) const {
    std::int64_t k = 0;
    for (int a = 0; a < D; ++a) k += std::int64_t(cell[a] - lo_[a]) * stride_[a];
    return k;
  }
  /// Slab layer (position along the slab axis within the window) of a key.
  int layer(std::int64_t key) const { return int(key / stride_[slab_]); }
  int layers() const { return hi_[slab_] - lo_[slab_] + 1; }
  /// Node index distance between two slab layers: the nodes of layer l are
  /// [l * layer_stride(), (l + 1) * layer_stride()).
  std::int64_t layer_stride() const { return stride_[slab_]; }
  int slab_axis() const { return slab_; }
  /// Offset of corner c of a cell from its lower corner node.
  std::int64_t corner(int c) const { return corner_[c]; }
  /// Global node index (lattice numbering) of a window node.
  IVec<D> global_node(std::int64_t index) const;
  /// The box of global nodes [lo, hi] the window spans (a decomposition's shared nodes).
  void node_box(IVec<D>& lo, IVec<D>& hi) const { lo = lo_, hi = hi_ + IVec<D>::Ones(); }
  /// Index of the window node at global node k, -1 when the window has none there.
  std::int64_t node_at(const IVec<D>& k) const {
    std::int64_t idx = 0;
    for (int a = 0; a < D; ++a) {
      if (k[a] < lo_[a] || k[a] > hi_[a] + 1) return -1;
      idx += std::int64_t(k[a] - lo_[a]) * stride_[a];
    }
    return idx;
  }

  // Node data and constrained nodes: GridNodes.

 protected:
  Lattice lattice_;
  int ghost_ = 0;
  IVec<D> lo_, hi_;  ///< window cells (inclusive)
  IVec<D> nodes_;    ///< window nodes per axis
  std::array<std::int64_t, D> stride_{};
  std::array<std::int64_t, kCorners<D>> corner_{};
  int slab_ = D - 1;
};

static_assert(Grid<UniformGrid<2>> && Grid<UniformGrid<3>>);

}  // namespace mpm
