// The graded grid (004, sections 3.1-3.2): levels, cells and hanging nodes counted by hand;
// values continuous across every level interface (evaluated from both sides); a linear field
// reproduced exactly through transition cells (patch test); a point walking across the levels
// keeps weights that sum to one; the slab layers the lock-free scatter relies on; the GRID
// record; and the messages for level boxes that break the rules.
#include <gtest/gtest.h>

#include <random>

#include "mpm/core/error.hpp"
#include "mpm/grid/graded_grid.hpp"
#include "mpm/grid/lattice.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm {
namespace {

LevelSpec box(int level, const Vec3& lo, const Vec3& hi, int index) {
  LevelSpec l;
  l.level = level;
  l.min = lo;
  l.max = hi;
  l.loc = {"scene.toml", 20 + index, "grid.levels." + std::to_string(index)};
  return l;
}

/// A domain of n^D cells of 1 mm from the origin with the given level boxes (mm).
Scene graded_scene(int dim, int n, std::vector<LevelSpec> levels, Lattice& lat) {
  Scene s;
  s.source = "scene.toml";
  s.dimension = dim;
  s.grid.cell_size = 1e-3;
  s.grid.domain_given = true;
  s.grid.domain_max = Vec3::Constant(n * 1e-3);
  if (dim == 2) s.grid.domain_max.z() = 0;
  for (auto& l : levels) l.min *= 1e-3, l.max *= 1e-3;
  s.grid.levels = levels;
  lat.dim = dim;
  lat.origin = Vec3::Zero();
  lat.h = 1e-3;
  lat.cells = {n, n, dim == 3 ? n : 1};
  return s;
}

/// The nested example: 8^3 cells, level 2 over [2, 6]^3 mm, level 3 over [3, 5]^3 mm.
template <int D>
GradedGrid<D> nested() {
  Lattice lat;
  const Scene s = graded_scene(D, 8,
                               {box(2, Vec3::Constant(2), Vec3::Constant(6), 0),
                                box(3, Vec3::Constant(3), Vec3::Constant(5), 1)},
                               lat);
  return GradedGrid<D>(lat, s);
}

TEST(GradedGrid, CountsCellsTransitionCellsAndHangingNodes) {
  const GradedGrid<3> g = nested<3>();
  ASSERT_EQ(g.levels(), 3);
  const auto n = g.cells_per_level();
  EXPECT_EQ(n[1], 512u - 64u);  // 8^3 level-1 cells, 4^3 of them refined
  EXPECT_EQ(n[2], 512u - 64u);  // 8^3 level-2 cells in the box, 4^3 of them refined
  EXPECT_EQ(n[3], 512u);        // 8^3 level-3 cells
  // Coarse cells next to a box: 6 faces x 16 with a mid-face node (and its 4 edges), 12 edges
  // x 4 with one mid-edge node; the 8 corner neighbours share only a corner node.
  EXPECT_EQ(g.transition_cells(), 2u * (6 * 16 + 12 * 4));
  // Hanging nodes: the finer lattice's nodes on each box surface that the coarser lattice
  // does not have: (9^3 - 7^3) - (5^3 - 3^3) per box.
  EXPECT_EQ(g.hanging_nodes(), 2u * ((729 - 343) - (125 - 27)));
  EXPECT_DOUBLE_EQ(g.min_cell_size(), 0.25e-3);
  const GradedGrid<2> g2 = nested<2>();
  EXPECT_EQ(g2.transition_cells(), 2u * (4 * 4));  // 4 edges x 4 cells
  EXPECT_EQ(g2.hanging_nodes(), 2u * (32 - 16));   // fine minus coarse nodes on each perimeter
}

/// Random nodal values; the value at x from the cell `key` (x may lie on the cell's boundary).
template <int D>
double interpolate(const GradedGrid<D>& g, std::int64_t key, const Vec<D>& x,
                   const std::vector<double>& u) {
  Vec<D> xi = (x - g.cell_origin(key)) / g.cell_h(key);
  for (int a = 0; a < D; ++a) xi[a] = std::clamp(xi[a], 0.0, 1.0);
  double N[GradedGrid<D>::kMaxNodes];
  std::int64_t nodes[GradedGrid<D>::kMaxNodes];
  g.values(key, xi, N);
  const int n = g.cell_nodes(key, nodes);
  double v = 0;
  for (int k = 0; k < n; ++k) v += N[k] * u[nodes[k]];
  return v;
}

// Every face of every cell: points on it evaluated from the cell and from the cell across it
// (found by stepping off the face) agree, for an arbitrary nodal field. Where the two cells
// are of different levels this is the continuity of the transition functions across the
// level interface. Tolerance 1e-13: sums of O(1) products.
template <int D>
void continuity() {
  const GradedGrid<D> g = nested<D>();
  std::mt19937 rng(1 + D);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::vector<double> u(g.nodes());
  for (auto& v : u) v = u01(rng);
  long interface_points = 0;
  for (std::int64_t key = 0; key < std::int64_t(g.key_count()); ++key) {
    const double h = g.cell_h(key);
    for (int face = 0; face < 2 * D; ++face) {
      const int axis = face / 2, side = face % 2;
      for (int s = 0; s < 4; ++s) {
        Vec<D> xi;
        for (int a = 0; a < D; ++a) xi[a] = u01(rng);
        xi[axis] = side;
        const Vec<D> x = g.cell_origin(key) + h * xi;
        Vec<D> off = x;
        off[axis] += (side ? 1 : -1) * 1e-3 * g.min_cell_size();
        std::int64_t other;
        Vec<D> oxi;
        if (g.where(off, other, oxi) != Where::Window) continue;  // the domain's face
        if (g.cell_level(other) != g.cell_level(key)) ++interface_points;
        ASSERT_NEAR(interpolate(g, key, x, u), interpolate(g, other, x, u), 1e-13)
            << "cell " << key << " (level " << g.cell_level(key) << ") and cell " << other
            << " (level " << g.cell_level(other) << ")";
      }
    }
  }
  EXPECT_GT(interface_points, D == 3 ? 2000 : 100);
}

TEST(GradedGrid, ContinuousAcrossEveryLevelInterface3D) {
  continuity<3>();
}
TEST(GradedGrid, ContinuousAcrossEveryLevelInterface2D) {
  continuity<2>();
}

// Patch test: nodal values of a linear velocity field v = v0 + B x; every cell, transition
// cells included, reproduces v and its gradient B exactly at any point. Tolerances: 1e-12 of
// the field's scale (rounding in sums of up to 26 terms).
template <int D>
void patch_test() {
  const GradedGrid<D> g = nested<D>();
  Mat<D> B;
  Vec<D> v0;
  for (int a = 0; a < D; ++a) {
    v0[a] = 10.0 * (a + 1);
    for (int b = 0; b < D; ++b) B(a, b) = 1e3 * (1.0 + a - 0.7 * b);
  }
  std::vector<Vec<D>> v(g.nodes());
  for (std::size_t n = 0; n < g.nodes(); ++n) v[n] = v0 + B * g.node_position(std::int64_t(n));
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  int transition = 0;
  for (std::int64_t key = 0; key < std::int64_t(g.key_count()); ++key) {
    transition += g.cell_mask(key) != 0;
    for (int s = 0; s < 3; ++s) {
      Vec<D> xi;
      for (int a = 0; a < D; ++a) xi[a] = u01(rng);
      const Vec<D> x = g.cell_origin(key) + g.cell_h(key) * xi;
      double N[GradedGrid<D>::kMaxNodes];
      Vec<D> G[GradedGrid<D>::kMaxNodes];
      std::int64_t nodes[GradedGrid<D>::kMaxNodes];
      g.shape(key, xi, N, G);
      const int n = g.cell_nodes(key, nodes);
      Vec<D> vp = Vec<D>::Zero();
      Mat<D> L = Mat<D>::Zero();
      for (int k = 0; k < n; ++k) {
        vp += N[k] * v[nodes[k]];
        L += v[nodes[k]] * G[k].transpose();
      }
      const Vec<D> exact = v0 + B * x;
      ASSERT_LT((vp - exact).norm(), 1e-12 * exact.norm()) << "cell " << key;
      ASSERT_LT((L - B).norm(), 1e-10 * B.norm()) << "cell " << key << " mask " << g.cell_mask(key);
    }
  }
  EXPECT_GT(transition, 0);
}

TEST(GradedGrid, PatchTestLinearVelocityThroughTransitionCells3D) {
  patch_test<3>();
}
TEST(GradedGrid, PatchTestLinearVelocityThroughTransitionCells2D) {
  patch_test<2>();
}

// A point walking along a diagonal through levels 1, 2, 3, 2, 1 in steps of 1/37 of the
// finest cell: its weights stay non-negative and sum to one (to rounding, 1e-14), and its
// cell, found from fine to coarse, changes level at every interface.
template <int D>
void walk() {
  const GradedGrid<D> g = nested<D>();
  Vec<D> dir = Vec<D>::Ones();
  dir[0] = 1.3;
  dir.normalize();
  const Vec<D> start = Vec<D>::Constant(0.3e-3);
  int last_level = 0, changes = 0;
  for (int s = 0;; ++s) {
    const Vec<D> x = start + (s * g.min_cell_size() / 37) * dir;
    std::int64_t key;
    Vec<D> xi;
    if (g.where(x, key, xi) != Where::Window) break;
    double N[GradedGrid<D>::kMaxNodes];
    g.values(key, xi, N);
    const int n = g.cell_nodes(key, std::array<std::int64_t, GradedGrid<D>::kMaxNodes>().data());
    double sum = 0;
    for (int k = 0; k < n; ++k) {
      ASSERT_GE(N[k], -1e-15);
      sum += N[k];
    }
    ASSERT_NEAR(sum, 1.0, 1e-14) << "at step " << s;
    if (g.cell_level(key) != last_level) ++changes, last_level = g.cell_level(key);
  }
  EXPECT_EQ(changes, 5);  // 1, 2, 3, 2, 1
}

// The kernels' bin fast path (in_cell) must agree bit for bit with locate: the same cell,
// the same local coordinates, for random points and for points on cell faces of every level
// (where rounding would show first), and it must refuse every other cell.
template <int D>
void in_cell_matches_locate() {
  const GradedGrid<D> g = nested<D>();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 8e-3);
  std::uniform_int_distribution<int> face(0, 32);
  for (int t = 0; t < 200000; ++t) {
    Vec<D> x;
    for (int a = 0; a < D; ++a) {
      x[a] = u(rng);
      if (t % 2) x[a] = face(rng) * 0.25e-3;  // on faces of level-3 cells (0.25 mm)
    }
    std::int64_t key;
    Vec<D> xi;
    if (g.where(x, key, xi) != Where::Window) continue;
    Vec<D> xi2;
    ASSERT_TRUE(g.in_cell(x, key, xi2)) << "point " << x.transpose();
    for (int a = 0; a < D; ++a) ASSERT_EQ(xi2[a], xi[a]);
    const std::int64_t other = (key + 1 + t % 7) % std::int64_t(g.key_count());
    if (other != key) {
      ASSERT_FALSE(g.in_cell(x, other, xi2));
    }
  }
}

TEST(GradedGrid, BinFastPathAgreesWithLocateBitForBit3D) {
  in_cell_matches_locate<3>();
}
TEST(GradedGrid, BinFastPathAgreesWithLocateBitForBit2D) {
  in_cell_matches_locate<2>();
}

TEST(GradedGrid, WalkingPointKeepsWeightsSummingToOne3D) {
  walk<3>();
}
TEST(GradedGrid, WalkingPointKeepsWeightsSummingToOne2D) {
  walk<2>();
}

// Keys are in slab-layer order, and a node is shared only by cells of one layer or of two
// adjacent ones: chunks of whole layers two apart never touch the same node (binning.hpp).
TEST(GradedGrid, LayersAreContiguousAndOnlyNeighbourLayersShareNodes) {
  const GradedGrid<3> g = nested<3>();
  std::vector<int> lo(g.nodes(), 1 << 30), hi(g.nodes(), -1);
  for (std::int64_t key = 0; key < std::int64_t(g.key_count()); ++key) {
    if (key > 0) {
      ASSERT_LE(g.layer(key - 1), g.layer(key));
    }
    std::int64_t nodes[26];
    const int n = g.cell_nodes(key, nodes);
    for (int k = 0; k < n; ++k) {
      lo[nodes[k]] = std::min(lo[nodes[k]], g.layer(key));
      hi[nodes[k]] = std::max(hi[nodes[k]], g.layer(key));
    }
  }
  for (std::size_t n = 0; n < g.nodes(); ++n) ASSERT_LE(hi[n] - lo[n], 1) << "node " << n;
  EXPECT_EQ(g.layers(), 8);
}

TEST(GradedGrid, GridRecordRoundTripAndDamage) {
  const GradedGrid<3> g = nested<3>();
  const GridMesh m = g.mesh(12, 3e-6);
  const std::vector<std::byte> b = encode_grid(m);
  const GridMesh r = decode_grid(b);
  EXPECT_EQ(r.dim, 3);
  EXPECT_EQ(r.levels, 3);
  EXPECT_EQ(r.step, 12);
  EXPECT_EQ(r.time, 3e-6);
  EXPECT_EQ(r.x, m.x);
  EXPECT_EQ(r.level, m.level);
  EXPECT_EQ(r.corners, m.corners);
  EXPECT_EQ(r.mask, m.mask);
  EXPECT_EQ(r.optional, m.optional);
  EXPECT_EQ(r.optional.size(), 2u * (6 * 16 * 5 + 12 * 4 * 1));  // a face and its 4 edges; an edge
  std::vector<std::byte> cut(b.begin(), b.end() - 3);
  EXPECT_THROW(decode_grid(cut), StreamError);
  std::vector<std::byte> bad = b;
  bad[bad.size() - 1] = std::byte{0xff};  // a node index out of range
  EXPECT_THROW(decode_grid(bad), StreamError);
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

std::string build_error(int dim, std::vector<LevelSpec> levels) {
  Lattice lat;
  const Scene s = graded_scene(dim, 8, std::move(levels), lat);
  try {
    if (dim == 3)
      GradedGrid<3>(lat, s);
    else
      GradedGrid<2>(lat, s);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(GradedGrid, RejectsBoxesThatBreakTheRules) {
  // A level-3 box against the side of the level-2 box: cells two levels apart would touch.
  EXPECT_PRED2(contains,
               build_error(3, {box(2, Vec3::Constant(2), Vec3::Constant(6), 0),
                               box(3, Vec3(2, 3, 3), Vec3(4, 5, 5), 1)}),
               "scene.toml:21: grid.levels.1: the level-3 box");
  EXPECT_PRED2(contains,
               build_error(3, {box(2, Vec3::Constant(2), Vec3::Constant(6), 0),
                               box(3, Vec3(2, 3, 3), Vec3(4, 5, 5), 1)}),
               "closer than one level-2 cell (0.5 mm)");
  // At the domain's face the same contact is fine.
  EXPECT_EQ(build_error(3, {box(2, Vec3(0, 2, 2), Vec3(4, 6, 6), 0),
                            box(3, Vec3(0, 3, 3), Vec3(2, 5, 5), 1)}),
            "");
  // Not nested.
  EXPECT_PRED2(contains,
               build_error(3, {box(2, Vec3::Constant(2), Vec3::Constant(4), 0),
                               box(3, Vec3::Constant(5), Vec3::Constant(6), 1)}),
               "is not inside the level-2 region");
  // Not on the coarser lattice.
  EXPECT_PRED2(contains, build_error(3, {box(2, Vec3(2.5, 2, 2), Vec3::Constant(6), 0)}),
               "grid.levels.0.min: must lie on the level-1 lattice");
  EXPECT_PRED2(contains, build_error(3, {box(3, Vec3::Constant(2), Vec3::Constant(6), 0)}),
               "needs level-2 boxes around it");
  // Two level-2 boxes in an L: the coarse cell in the inner corner would have negative
  // shape functions (transition_shape tests).
  EXPECT_PRED2(contains,
               build_error(3, {box(2, Vec3(2, 2, 2), Vec3(4, 6, 6), 0),
                               box(2, Vec3(4, 4, 2), Vec3(6, 6, 6), 1)}),
               "concave corner");
  EXPECT_PRED2(contains,
               build_error(2, {box(2, Vec3(2, 2, 0), Vec3(4, 6, 0), 0),
                               box(2, Vec3(4, 4, 0), Vec3(6, 6, 0), 1)}),
               "concave corner");
  // Two boxes one coarse cell apart on opposite sides of it are fine.
  EXPECT_EQ(build_error(3, {box(2, Vec3(2, 2, 2), Vec3(4, 6, 6), 0),
                            box(2, Vec3(5, 2, 2), Vec3(7, 6, 6), 1)}),
            "");
}

// Scene keys: [[grid.levels]] parsed, and mistakes named by file, line and key.
TEST(GradedGrid, SceneKeysAndMessages) {
  const std::string head = R"([materials.m]
density = 1000
youngs_modulus = 1e9
poisson_ratio = 0.3
[[bodies]]
name = "b"
material = "m"
shape = "box"
size = "4 4 4 mm"
translate = "5 5 5 mm"
[solver]
end_time = 1e-6
[grid]
cell_size = "1 mm"
domain = { min = "0 0 0 mm", max = "10 10 10 mm" }
)";
  const Scene s = parse_scene(head + R"([[grid.levels]]
level = 2
min = "3 3 3 mm"
max = "7 7 7 mm"
follow = "b"
)",
                              "s.toml", "", {});
  ASSERT_EQ(s.grid.levels.size(), 1u);
  EXPECT_EQ(s.grid.levels[0].level, 2);
  EXPECT_DOUBLE_EQ(s.grid.levels[0].max.x(), 7e-3);
  EXPECT_EQ(s.grid.levels[0].follow, 0);
  EXPECT_EQ(s.grid.level_count(), 2);
  auto error = [&](const std::string& levels, std::vector<std::string> set = {}) {
    try {
      parse_scene(head + levels, "s.toml", "", set);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  // A body's own particle spacing does not follow the levels' cells.
  EXPECT_EQ(error("[[grid.levels]]\nlevel = 2\nmin = \"3 3 3 mm\"\nmax = \"7 7 7 mm\"\n",
                  {"bodies.b.particle_spacing=0.3 mm"}),
            "--set bodies.b.particle_spacing: a graded grid ([[grid.levels]]) sets each level's "
            "spacing from its cells: use particles_per_cell");
  EXPECT_EQ(error("[[grid.levels]]\nlevel = 2\nmin = \"3.5 3 3 mm\"\nmax = \"7 7 7 mm\"\n"),
            "s.toml:18: grid.levels.0.min: a level-2 box must lie on the level-1 lattice: x = 3.5 "
            "mm is not a multiple of 1 mm from grid.domain.min (nearest: 4 mm)");
  EXPECT_EQ(
      error("[[grid.levels]]\nlevel = 2\nmin = \"3 3 3 mm\"\nmax = \"7 7 7 mm\"\nsize = 3\n"),
      "s.toml:20: grid.levels.0.size: unknown key (expected one of: level, min, max, follow)");
  EXPECT_EQ(error("[[grid.levels]]\nlevel = 1\nmin = \"3 3 3 mm\"\nmax = \"7 7 7 mm\"\n"),
            "s.toml:17: grid.levels.0.level: must be between 2 and 12, got 1");
  EXPECT_EQ(
      error("[[grid.levels]]\nlevel = 2\nmin = \"3 3 3 mm\"\nmax = \"7 7 7 mm\"\nfollow = \"x\"\n"),
      "s.toml:20: grid.levels.0.follow: unknown body 'x' (known: b)");
  EXPECT_EQ(error("[[grid.levels]]\nlevel = 2\nmin = \"3 3 3 mm\"\nmax = \"7 7 12 mm\"\n"),
            "s.toml:19: grid.levels.0.max: the box leaves grid.domain along z");
  EXPECT_EQ(error("[[grid.levels]]\nlevel = 2\nmin = \"3 3 3 mm\"\nmax = \"7 7 7 mm\"\n",
                  {"grid.levels.0.min=\"3 3 3.5 mm\""}),
            "--set grid.levels.0.min: a level-2 box must lie on the level-1 lattice: z = 3.5 mm is "
            "not a multiple of 1 mm from grid.domain.min (nearest: 4 mm)");
}

}  // namespace
}  // namespace mpm
