// The mesh-grading background grid: building the levels, cells, nodes and transition cells
// from the scene's level boxes (004, section 3.2), following a body, and the GRID record.
#include "mpm/grid/graded_grid.hpp"

#include <omp.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <stdexcept>

#include "mpm/core/error.hpp"
#include "mpm/core/units.hpp"

namespace mpm {

namespace {

/// Visits every cell of a box of cells [lo, hi).
template <int D, class F>
void for_cells(const IVec<D>& lo, const IVec<D>& hi, F&& f) {
  for (int a = 0; a < D; ++a)
    if (hi[a] <= lo[a]) return;
  IVec<D> c = lo;
  while (true) {
    f(c);
    int a = 0;
    while (a < D && ++c[a] == hi[a]) c[a] = lo[a], ++a;
    if (a == D) break;
  }
}

}  // namespace

template <int D>
std::string GradedGrid<D>::mm(const Vec<D>& x) const {
  std::string s;
  for (int a = 0; a < D; ++a) {
    if (a) s += ' ';
    s += format_mm(x[a]);
  }
  return s + " mm";
}

template <int D>
void GradedGrid<D>::fail(const Box& b, const std::string& key, const std::string& message) const {
  throw InputError(mpm::where(b.loc.file, b.loc.line, b.loc.key + (key.empty() ? "" : "." + key)),
                   message);
}

template <int D>
GradedGrid<D>::GradedGrid(const Lattice& lattice, const Scene& scene)
    : lattice_(lattice), boundary_(scene.boundary) {
  if (lattice.dim != D) throw std::logic_error("lattice dimension does not match the solver");
  h1_ = lattice.h;
  inv_h1_ = 1.0 / h1_;
  for (int a = 0; a < D; ++a) {
    origin_[a] = lattice.origin[a];
    cells1_[a] = lattice.cells[a];
  }
  levels_ = 1;
  for (const LevelSpec& s : scene.grid.levels) levels_ = std::max(levels_, s.level);
  if (levels_ > 12) throw std::logic_error("graded grid: at most 12 levels");
  level_.resize(levels_ + 1);
  for (int l = 1; l <= levels_; ++l) {
    Level& lv = level_[l];
    lv.scale = std::ldexp(1.0, l - 1);
    lv.h = std::ldexp(h1_, -(l - 1));
    lv.inv_h = inv_h1_ * lv.scale;
    inv_h_[l] = lv.inv_h;
    scale_[l] = lv.scale;
  }
  wn_ = cells1_;  // the whole domain first: the boxes are checked on it
  h_fine_ = level_[levels_].h;
  // Slab axis: the domain's longest (ties to the highest axis), as UniformGrid.
  slab_ = D - 1;
  for (int a = D - 2; a >= 0; --a)
    if (cells1_[a] > cells1_[slab_]) slab_ = a;

  // Level boxes in cells of their level, checked against the coarser lattice and the domain.
  for (std::size_t k = 0; k < scene.grid.levels.size(); ++k) {
    const LevelSpec& s = scene.grid.levels[k];
    Box b;
    b.level = s.level;
    b.loc = s.loc;
    b.index = int(k);
    if (s.level < 2) fail(b, "level", "must be 2 or more (level 1 is the whole domain)");
    const double hp = level_[s.level - 1].h;  // the coarser lattice the box is aligned to
    const double cells_l = std::ldexp(1.0, s.level - 1);
    for (int a = 0; a < D; ++a) {
      const double corner[2] = {s.min[a], s.max[a]};
      int idx[2];
      for (int e = 0; e < 2; ++e) {
        const double r = (corner[e] - origin_[a]) / hp;
        const double n = std::round(r);
        if (std::abs(r - n) > 1e-6) {
          Vec<D> near = Vec<D>::Zero();
          for (int c = 0; c < D; ++c)
            near[c] = origin_[c] + hp * std::round(((e ? s.max : s.min)[c] - origin_[c]) / hp);
          fail(b, e ? "max" : "min",
               std::string("must lie on the level-") + std::to_string(s.level - 1) +
                   " lattice (multiples of " + format_mm(hp) + " mm from grid.domain.min) but " +
                   axis_name(a) + " is off it; nearest: " + mm(near));
        }
        idx[e] = int(n) * 2;
      }
      if (idx[0] < 0 || double(idx[1]) > cells1_[a] * cells_l)
        fail(b, idx[0] < 0 ? "min" : "max",
             std::string("the box leaves the grid domain along ") + axis_name(a));
      if (idx[1] <= idx[0])
        fail(b, "max",
             std::string("the box must span at least one level-") + std::to_string(s.level - 1) +
                 " cell along " + axis_name(a));
      b.lo[a] = idx[0];
      b.hi[a] = idx[1];
    }
    boxes_.push_back(b);
  }
  // Following: every box follows one body, with one box per level (a nested chain that moves
  // as a whole), or none does.
  for (std::size_t k = 0; k < scene.grid.levels.size(); ++k) {
    const int f = scene.grid.levels[k].follow;
    if (k == 0) follow_body_ = f;
    if (f != follow_body_)
      fail(boxes_[k], "follow",
           "either every level box follows the same body or none does (here: " +
               std::string(f < 0 ? "none" : "'" + scene.bodies[f].name + "'") + ", box 0: " +
               (follow_body_ < 0 ? "none" : "'" + scene.bodies[follow_body_].name + "'") + ")");
  }
  if (follow_body_ >= 0) {
    for (std::size_t k = 0; k < boxes_.size(); ++k)
      for (std::size_t j = 0; j < k; ++j)
        if (boxes_[j].level == boxes_[k].level)
          fail(boxes_[k], "follow",
               "boxes that follow a body must be one per level (level " +
                   std::to_string(boxes_[k].level) + " has two)");
  }
  build(true);
  revision_ = 1;
}

template <int D>
bool GradedGrid<D>::build(bool validate) {
  ++builds_;
  place_boxes();
  build_regions(validate);
  if (validate) check_nesting();  // checked on the whole domain; clipping keeps the rules
  mark_refined();
  const std::vector<IVec<D>> cpos = number_cells();
  if (cells_.size() > std::size_t(std::numeric_limits<std::int32_t>::max()))
    throw std::runtime_error("graded grid of " + std::to_string(cells_.size()) +
                             " cells exceeds 2^31; use larger cells");
  std::vector<Level> nodes_of = number_nodes(cpos);
  if (!add_optional_nodes(cpos, nodes_of, validate)) return false;
  set_boundary_nodes();

  info_.resize(cells_.size());
  cell_lo_.resize(cells_.size());
  for (std::size_t key = 0; key < cells_.size(); ++key) {
    info_[key] = cells_[key].mask | (std::uint32_t(cells_[key].level) << kLevelShift);
    cell_lo_[key] = cpos[key].template cast<double>();
  }

  const std::size_t nn = node_ijk_.size();
  m.resize(nn);
  v.resize(nn);
  a.resize(nn);
  if (!v_remap.empty()) v_remap.resize(nn);
  if (!rigid.empty()) rigid.resize(nn);
  built_offset_ = offset_;
  return true;
}

template <int D>
void GradedGrid<D>::place_boxes() {
  // Slab axis: the window's longest (ties to the highest axis), as UniformGrid.
  slab_ = D - 1;
  for (int a = D - 2; a >= 0; --a)
    if (wn_[a] > wn_[slab_]) slab_ = a;
  std::int64_t st = 1;
  for (int a = 0; a < D; ++a) stride1_[a] = st, st *= wn_[a];
  // Box extents at the current offset.
  for (Box& b : boxes_) {
    const int s = 1 << (b.level - 1);
    for (int a = 0; a < D; ++a) {
      b.xmin[a] = origin_[a] + level_[b.level].h * double(b.lo[a] + offset_[a] * s);
      b.xmax[a] = origin_[a] + level_[b.level].h * double(b.hi[a] + offset_[a] * s);
    }
  }
}

template <int D>
bool GradedGrid<D>::clipped(const Box& b, IVec<D>& lo, IVec<D>& hi) const {
  const int s = 1 << (b.level - 1);
  lo = (b.lo + offset_ * s).cwiseMax(wlo_ * s);
  hi = (b.hi + offset_ * s).cwiseMin((wlo_ + wn_) * s);
  for (int a = 0; a < D; ++a)
    if (hi[a] <= lo[a]) return false;
  return true;
}

template <int D>
void GradedGrid<D>::build_regions(bool validate) {
  // Level regions: level 1 is the window; level l the union of its boxes.
  level_[1].layout(wlo_, wlo_ + wn_);
  std::fill(level_[1].cell.begin(), level_[1].cell.end(), 0);
  for (int l = 2; l <= levels_; ++l) {
    IVec<D> lo = IVec<D>::Constant(std::numeric_limits<int>::max());
    IVec<D> hi = IVec<D>::Constant(std::numeric_limits<int>::min());
    bool any = false;
    for (const Box& b : boxes_)
      if (b.level == l) {
        IVec<D> blo, bhi;
        if (!clipped(b, blo, bhi)) continue;
        lo = lo.cwiseMin(blo);
        hi = hi.cwiseMax(bhi);
        any = true;
      }
    if (!any && validate) {
      for (const Box& b : boxes_)
        if (b.level > l)
          fail(b, "level",
               "a level-" + std::to_string(b.level) + " box needs level-" + std::to_string(l) +
                   " boxes around it (levels are nested)");
    }
    if (!any) lo = hi = IVec<D>::Zero();
    Level& lv = level_[l];
    lv.layout(lo, hi);
    for (const Box& b : boxes_) {
      IVec<D> blo, bhi;
      if (b.level == l && clipped(b, blo, bhi))
        for_cells<D>(blo, bhi, [&](const IVec<D>& c) { lv.cell[lv.index(c)] = 0; });
    }
  }
}

template <int D>
void GradedGrid<D>::check_nesting() const {
  // Nesting (each box inside the coarser region) and 2:1 balance: a level-l box (l >= 3)
  // grown by one level-(l-1) cell on every side must stay inside the level-(l-1) region,
  // except where it meets the domain's faces, so that cells touching at a face, an edge or a
  // corner differ by at most one level.
  for (const Box& b : boxes_) {
    const int l = b.level;
    IVec<D> blo, bhi;
    clipped(b, blo, bhi);
    const Level& parent = level_[l - 1];
    const IVec<D> plo = blo / 2, phi = bhi / 2;
    const auto in_parent = [&](const IVec<D>& lo, const IVec<D>& hi) {
      bool in = true;
      for_cells<D>(lo, hi, [&](const IVec<D>& c) {
        if (!parent.holds(c) || parent.cell[parent.index(c)] == kNotInLevel) in = false;
      });
      return in;
    };
    if (!in_parent(plo, phi))
      fail(b, "",
           "the level-" + std::to_string(l) + " box [" + mm(b.xmin) + ", " + mm(b.xmax) +
               "] is not inside the level-" + std::to_string(l - 1) +
               " region (levels are nested)");
    if (l < 3) continue;
    IVec<D> glo = plo - IVec<D>::Ones(), ghi = phi + IVec<D>::Ones();
    const int sp = 1 << (l - 2);
    for (int a = 0; a < D; ++a) {
      glo[a] = std::max(glo[a], 0);
      ghi[a] = std::min(ghi[a], cells1_[a] * sp);
    }
    if (!in_parent(glo, ghi))
      fail(b, "",
           "the level-" + std::to_string(l) + " box [" + mm(b.xmin) + ", " + mm(b.xmax) +
               "] comes closer than one level-" + std::to_string(l - 1) + " cell (" +
               format_mm(parent.h) + " mm) to the edge of the level-" + std::to_string(l - 1) +
               " region; keep that margin (except at the domain's faces) so that "
               "neighbouring cells differ by one level at most");
  }
}

template <int D>
void GradedGrid<D>::mark_refined() {
  // Refined cells: a level-(l-1) cell covered by level-l cells is no leaf.
  for (int l = levels_; l >= 2; --l)
    for (const Box& b : boxes_) {
      IVec<D> blo, bhi;
      if (b.level != l || !clipped(b, blo, bhi)) continue;
      Level& parent = level_[l - 1];
      for_cells<D>(blo / 2, bhi / 2,
                   [&](const IVec<D>& c) { parent.cell[parent.index(c)] = kRefined; });
    }
}

template <int D>
std::vector<IVec<D>> GradedGrid<D>::number_cells() {
  // Cell keys: level-1 cells with the slab axis slowest, the leaves inside each depth first;
  // locate's tree on the way.
  cells_.clear();
  std::vector<IVec<D>> cpos;  // leaf position in cells of its level
  std::size_t refined = 0;
  for (int l = 1; l < levels_; ++l)
    refined += std::size_t(std::count(level_[l].cell.begin(), level_[l].cell.end(), kRefined));
  root_.assign(level_[1].cell.size(), -1);
  tree_.assign(refined << D, -1);  // sized once: the slots below stay valid
  std::size_t next = 0;
  int order[D];
  int k = 0;
  for (int a = 0; a < D; ++a)
    if (a != slab_) order[k++] = a;
  order[D - 1] = slab_;  // slowest
  auto visit = [&](auto&& self, int l, const IVec<D>& c, int layer, std::int32_t& slot) -> void {
    Level& lv = level_[l];
    const std::int64_t idx = lv.index(c);
    if (lv.cell[idx] == kRefined) {
      const std::size_t t = next++;
      slot = std::int32_t(-1 - std::int64_t(t));
      for (int bits = 0; bits < kCorners<D>; ++bits) {
        IVec<D> child;
        for (int a = 0; a < D; ++a) child[a] = 2 * c[a] + ((bits >> a) & 1);
        self(self, l + 1, child, layer, tree_[(t << D) + bits]);
      }
      return;
    }
    Cell cell;
    cell.level = std::uint8_t(l);
    cell.layer = layer;
    slot = lv.cell[idx] = std::int32_t(cells_.size());
    cells_.push_back(cell);
    cpos.push_back(c);
  };
  IVec<D> c = wlo_;
  while (true) {
    std::int64_t idx1 = 0;
    for (int a = 0; a < D; ++a) idx1 += (c[a] - wlo_[a]) * stride1_[a];
    visit(visit, 1, c, c[slab_] - wlo_[slab_], root_[idx1]);
    int q = 0;
    while (q < D && ++c[order[q]] == wlo_[order[q]] + wn_[order[q]])
      c[order[q]] = wlo_[order[q]], ++q;
    if (q == D) break;
  }
  return cpos;
}

template <int D>
std::int32_t* GradedGrid<D>::node_slot(std::vector<Level>& nodes_of, const IVec<D>& P) const {
  const int L = levels_;
  int tz = L - 1;
  for (int a = 0; a < D; ++a)
    if (P[a] != 0) tz = std::min(tz, std::countr_zero(unsigned(P[a])));
  const int k = L - tz;  // the coarsest level whose lattice holds P
  Level& nl = nodes_of[k];
  IVec<D> q;
  for (int a = 0; a < D; ++a) q[a] = P[a] >> (L - k);
  std::int64_t idx = 0;
  for (int a = 0; a < D; ++a) {
    const int c = q[a] - nl.lo[a];
    if (c < 0 || c >= nl.n[a]) return nullptr;
    idx += std::int64_t(c) * nl.stride[a];
  }
  return &nl.cell[idx];
}

template <int D>
std::vector<typename GradedGrid<D>::Level> GradedGrid<D>::number_nodes(
    const std::vector<IVec<D>>& cpos) {
  // Nodes: one list for all levels. A node is stored once, at the coarsest level whose
  // lattice holds it, in a dense array over that level's region (nodes of the bounding box).
  const int L = levels_;
  std::vector<Level> nodes_of(L + 1);
  for (int l = 1; l <= L; ++l) {
    Level& nl = nodes_of[l];
    nl.lo = level_[l].lo;
    nl.n = level_[l].n + IVec<D>::Ones();
    std::int64_t s = 1;
    for (int a = 0; a < D; ++a) nl.stride[a] = s, s *= nl.n[a];
    nl.cell.assign(std::size_t(s), -1);
  }
  node_ijk_.clear();
  node_level_.clear();
  for (std::size_t key = 0; key < cells_.size(); ++key) {
    Cell& cell = cells_[key];
    const int sh = L - cell.level;
    for (int c = 0; c < kCorners<D>; ++c) {
      IVec<D> P;
      for (int a = 0; a < D; ++a) P[a] = (cpos[key][a] + ((c >> a) & 1)) << sh;
      std::int32_t* s = node_slot(nodes_of, P);
      if (!s) throw std::logic_error("graded grid: a corner node lies outside its level's region");
      if (*s < 0) {
        *s = std::int32_t(node_ijk_.size());
        node_ijk_.push_back(P);
        node_level_.push_back(cell.level);
      }
      cell.corner[c] = *s;
      node_level_[*s] = std::min(node_level_[*s], cell.level);
    }
  }
  return nodes_of;
}

template <int D>
bool GradedGrid<D>::add_optional_nodes(const std::vector<IVec<D>>& cpos,
                                       std::vector<Level>& nodes_of, bool validate) {
  // Optional nodes: the mid-edge and mid-face points of a cell that are corners of finer
  // cells (hanging nodes), in increasing number (transition_shape.hpp).
  const int L = levels_;
  optional_.clear();
  hanging_.assign(node_ijk_.size(), 0);
  const TransitionTopology<D>& T = kTransition<D>;
  std::map<std::uint32_t, double> mask_min;
  for (std::size_t key = 0; key < cells_.size(); ++key) {
    Cell& cell = cells_[key];
    cell.opt = std::uint32_t(optional_.size());
    if (cell.level == L) continue;
    const int sh = L - cell.level - 1;  // half a cell, in finest cells: 2^sh
    for (int k = kCorners<D>; k < kTransitionNodes<D>; ++k) {
      IVec<D> P;
      for (int a = 0; a < D; ++a) P[a] = (cpos[key][a] << (sh + 1)) + ((T.p[k][a] + 1) << sh);
      const std::int32_t* s = node_slot(nodes_of, P);
      if (!s || *s < 0) continue;
      cell.mask |= 1u << (k - kCorners<D>);
      optional_.push_back(*s);
      hanging_[*s] = 1;
      node_level_[*s] = std::min(node_level_[*s], cell.level);
    }
    if (cell.mask == 0) continue;
    auto [it, fresh] = mask_min.try_emplace(cell.mask, 0.0);
    if (fresh) it->second = transition_min_value<D>(cell.mask);
    if (it->second < -1e-12 && !validate) return false;  // clipped badly: use a larger window
    if (it->second < -1e-12) fail_concave(cell, cpos[key]);
  }
  return true;
}

template <int D>
void GradedGrid<D>::fail_concave(const Cell& cell, const IVec<D>& pos) const {
  // Name the finer box nearest to the cell.
  Vec<D> centre;
  for (int a = 0; a < D; ++a) centre[a] = origin_[a] + level_[cell.level].h * (pos[a] + 0.5);
  const Box* nearest = &boxes_.front();
  double best = 1e300;
  for (const Box& b : boxes_) {
    if (b.level != cell.level + 1) continue;
    double d = 0;
    for (int a = 0; a < D; ++a)
      d += std::pow(std::max({b.xmin[a] - centre[a], centre[a] - b.xmax[a], 0.0}), 2);
    if (d < best) best = d, nearest = &b;
  }
  fail(*nearest, "",
       "the level-" + std::to_string(cell.level + 1) + " boxes meet the level-" +
           std::to_string(cell.level) + " cell at " + mm(centre) +
           " on two sides (a concave corner); its transition shape functions would be "
           "negative there. Merge the boxes into one, or keep them at least one level-" +
           std::to_string(cell.level) + " cell apart");
}

template <int D>
void GradedGrid<D>::set_boundary_nodes() {
  // Boundary conditions on the constrained domain faces (hanging nodes included).
  fixed_.clear();
  slip_.clear();
  for (std::size_t n = 0; n < node_ijk_.size(); ++n)
    for (int face = 0; face < 2 * D; ++face) {
      const BoundaryType type = boundary_.face[face];
      if (type == BoundaryType::Free) continue;
      const int axis = face / 2;
      const int plane = face % 2 == 0 ? 0 : cells1_[axis] << (levels_ - 1);
      if (node_ijk_[n][axis] != plane) continue;
      (type == BoundaryType::Fixed ? fixed_ : slip_).push_back({std::int64_t(n), face});
    }
}

template <int D>
void GradedGrid<D>::fit(const Vec<D>* x, std::size_t n, int margin) {
  IVec<D> lo, hi;  // level-1 cells of the particles
  cell_bounds<D>(x, n, origin_, inv_h1_, cells1_, lo, hi);
  auto clamp = [&](int pad, IVec<D>& wlo, IVec<D>& whi) {
    for (int a = 0; a < D; ++a) {
      wlo[a] = std::clamp(lo[a] - pad, 0, cells1_[a]);
      whi[a] = std::clamp(hi[a] + 1 + pad, 0, cells1_[a]);
    }
  };
  IVec<D> need_lo, need_hi, cur_hi = wlo_ + wn_;
  clamp(margin, need_lo, need_hi);
  const bool inside =
      (need_lo.array() >= wlo_.array()).all() && (need_hi.array() <= cur_hi.array()).all();
  // Shrink when the window holds more than twice the cells the particles need (with 3 around).
  IVec<D> roomy_lo, roomy_hi;
  clamp(3, roomy_lo, roomy_hi);
  const double want = (roomy_hi - roomy_lo).template cast<double>().prod();
  const bool oversized = wn_.template cast<double>().prod() > 2 * want;
  if (inside && !oversized && offset_ == built_offset_) return;
  const bool moved = offset_ != built_offset_;
  wlo_ = roomy_lo;
  wn_ = roomy_hi - roomy_lo;
  if (!build(false)) {  // the clipped boxes make a bad transition cell: the whole domain
    wlo_.setZero();
    wn_ = cells1_;
    build(false);
  }
  if (moved) ++revision_;
}

template <int D>
void GradedGrid<D>::save_state(StateValues& s) const {
  for (int a = 0; a < D; ++a) {
    const std::string x(1, "xyz"[a]);
    s.set("grid_window_lo_" + x, wlo_[a]);
    s.set("grid_window_n_" + x, wn_[a]);
    s.set("grid_offset_" + x, offset_[a]);
    s.set("grid_built_offset_" + x, built_offset_[a]);
    s.set("grid_centre0_" + x, centre0_[a]);
  }
  s.set("grid_have_centre0", have_centre0_ ? 1 : 0);
  s.set("grid_revision", double(revision_));
  s.set("grid_builds", double(builds_));
}

template <int D>
void GradedGrid<D>::restore_state(const StateValues& s) {
  IVec<D> offset;
  for (int a = 0; a < D; ++a) {
    const std::string x(1, "xyz"[a]);
    wlo_[a] = int(s.get("grid_window_lo_" + x));
    wn_[a] = int(s.get("grid_window_n_" + x));
    offset[a] = int(s.get("grid_offset_" + x));
    offset_[a] = int(s.get("grid_built_offset_" + x));
    centre0_[a] = s.get("grid_centre0_" + x);
  }
  have_centre0_ = s.get("grid_have_centre0") != 0;
  if (!build(false))
    throw InputError("checkpoint", "the graded grid's window it holds does not build");
  offset_ = offset;  // a move still pending takes effect at the next fit, as it would have
  revision_ = long(s.get("grid_revision"));
  builds_ = long(s.get("grid_builds"));
}

template <int D>
bool GradedGrid<D>::follow(const Vec<D>& centre) {
  if (follow_body_ < 0) return false;
  if (!have_centre0_) {
    centre0_ = centre;
    have_centre0_ = true;
    return false;
  }
  // The whole chain moves by whole level-1 cells, clamped to the domain.
  IVec<D> want;
  for (int a = 0; a < D; ++a) want[a] = int(std::lround((centre[a] - centre0_[a]) * inv_h1_));
  for (const Box& b : boxes_) {
    const int s = 1 << (b.level - 1);
    for (int a = 0; a < D; ++a) {
      const int lo = -(b.lo[a] / s), hi = (cells1_[a] * s - b.hi[a]) / s;
      want[a] = std::clamp(want[a], lo, hi);
    }
  }
  if (want == offset_) return false;
  // The chain keeps its shape, but a box that touched a domain face may leave it: keep the
  // margins build() checks (the grown level-l box inside the level-(l-1) box), or stay.
  for (const Box& b : boxes_) {
    if (b.level < 3) continue;
    const int sb = 1 << (b.level - 1), sp = 1 << (b.level - 2);
    for (const Box& p : boxes_) {
      if (p.level != b.level - 1) continue;
      for (int a = 0; a < D; ++a) {
        const int glo = std::max((b.lo[a] + want[a] * sb) / 2 - 1, 0);
        const int ghi = std::min((b.hi[a] + want[a] * sb) / 2 + 1, cells1_[a] * sp);
        if (glo < p.lo[a] + want[a] * sp || ghi > p.hi[a] + want[a] * sp) return false;
      }
    }
  }
  offset_ = want;
  return true;
}

template <int D>
void GradedGrid<D>::clear(bool remap, bool rigid_bodies) {
  const std::int64_t n = std::int64_t(m.size());
  if (remap && v_remap.size() != m.size()) v_remap.resize(m.size());
  if (rigid_bodies && rigid.size() != m.size()) rigid.resize(m.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) {
    m[i] = 0;
    v[i].setZero();
    a[i].setZero();
    if (remap) v_remap[i].setZero();
    if (rigid_bodies) rigid[i] = 0;
  }
}

template <int D>
void GradedGrid<D>::clear_remap() {
  const std::int64_t n = std::int64_t(m.size());
  if (v_remap.size() != m.size()) v_remap.resize(m.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < n; ++i) v_remap[i].setZero();
}

template <int D>
std::vector<std::size_t> GradedGrid<D>::cells_per_level() const {
  std::vector<std::size_t> n(levels_ + 1, 0);
  for (const Cell& c : cells_) ++n[c.level];
  return n;
}

template <int D>
std::size_t GradedGrid<D>::transition_cells() const {
  std::size_t n = 0;
  for (const Cell& c : cells_) n += c.mask != 0;
  return n;
}

template <int D>
std::size_t GradedGrid<D>::hanging_nodes() const {
  std::size_t n = 0;
  for (auto h : hanging_) n += h;
  return n;
}

template <int D>
GridMesh GradedGrid<D>::mesh(std::int64_t step, double time) const {
  if (wlo_ != IVec<D>::Zero() || wn_ != cells1_) {
    GradedGrid<D> whole = *this;  // the same boxes over the whole domain
    whole.m.clear(), whole.v.clear(), whole.a.clear(), whole.v_remap.clear(), whole.rigid.clear();
    whole.wlo_.setZero();
    whole.wn_ = cells1_;
    whole.build(false);
    return whole.mesh(step, time);
  }
  GridMesh g;
  g.dim = D;
  g.levels = levels_;
  g.step = step;
  g.time = time;
  g.x.resize(3 * node_ijk_.size(), 0.0);
  for (std::size_t n = 0; n < node_ijk_.size(); ++n) {
    const Vec<D> x = node_position(std::int64_t(n));
    for (int a = 0; a < D; ++a) g.x[3 * n + a] = x[a];
  }
  g.level.reserve(cells_.size());
  g.corners.reserve(cells_.size() * kCorners<D>);
  g.mask.reserve(cells_.size());
  for (const Cell& c : cells_) {
    g.level.push_back(c.level);
    for (int k = 0; k < kCorners<D>; ++k) g.corners.push_back(std::uint32_t(c.corner[k]));
    g.mask.push_back(c.mask);
  }
  g.optional.assign(optional_.begin(), optional_.end());
  return g;
}

template class GradedGrid<2>;
template class GradedGrid<3>;

}  // namespace mpm
