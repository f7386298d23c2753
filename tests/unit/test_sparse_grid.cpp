// The sparse grid activates the cells that hold particles widened by one cell, and only the
// corners of those cells are nodes; its keys follow the dense window's cell order.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <random>
#include <set>

#include "mpm/grid/grid.hpp"
#include "mpm/grid/lattice.hpp"
#include "mpm/grid/sparse_grid.hpp"

namespace mpm {
namespace {

Lattice lattice3(int n, double h) {
  Lattice l;
  l.dim = 3;
  l.h = h;
  l.cells = {n, n, n};
  return l;
}

// One particle in the middle of the domain: a 3 x 3 x 3 block of active cells, 4 x 4 x 4
// nodes. Two far apart: twice that, in a box of thousands of cells (what a dense window holds).
TEST(SparseGrid, ActivatesOccupiedCellsWidenedByOne) {
  const Lattice lat = lattice3(40, 1.0);
  SparseGrid<3> g(lat, BoundarySpec{});
  std::vector<Vec3> x{Vec3(10.5, 10.5, 10.5)};
  g.fit(x.data(), x.size());
  EXPECT_EQ(g.key_count(), 27u);
  EXPECT_EQ(g.nodes(), 64u);
  x.push_back(Vec3(30.5, 25.5, 20.5));
  g.fit(x.data(), x.size());
  EXPECT_EQ(g.key_count(), 54u);
  EXPECT_EQ(g.nodes(), 128u);
  EXPECT_EQ(g.box_cells(), std::size_t(23 * 18 * 13));
  UniformGrid<3> dense(lat, BoundarySpec{});
  dense.fit(x.data(), x.size());
  EXPECT_EQ(dense.nodes(), std::size_t(24 * 19 * 14));

  // Where: a particle's own cell and its neighbours are in; two cells away is out (a re-sort).
  std::int64_t key = -1;
  Vec3 xi;
  EXPECT_EQ(g.where(Vec3(11.9, 9.1, 10.5), key, xi), Where::Window);
  EXPECT_NEAR(xi[0], 0.9, 1e-12);
  EXPECT_EQ(g.where(Vec3(12.5, 10.5, 10.5), key, xi), Where::OutsideWindow);
  EXPECT_EQ(g.where(Vec3(20.5, 20.5, 15.5), key, xi), Where::OutsideWindow);  // inside the box
  EXPECT_EQ(g.where(Vec3(-0.5, 10.5, 10.5), key, xi), Where::OutsideDomain);
}

// In 2D: 3 x 3 cells and 4 x 4 nodes around a particle; a particle by a slip face gives that
// face's active nodes only.
TEST(SparseGrid, TwoDimensions) {
  Lattice lat;
  lat.dim = 2;
  lat.h = 0.1;
  lat.cells = {50, 50, 1};
  BoundarySpec b;
  b.face[2] = BoundaryType::Slip;  // y_min
  SparseGrid<2> g(lat, b);
  std::vector<Vec<2>> x{Vec<2>(2.05, 2.05), Vec<2>(4.05, 0.05)};
  g.fit(x.data(), x.size());
  EXPECT_EQ(g.key_count(), 9u + 6u);  // the second particle's row below is outside the domain
  EXPECT_EQ(g.nodes(), 16u + 12u);
  EXPECT_EQ(g.slip_nodes().size(), 4u);
  std::int64_t key;
  Vec<2> xi;
  EXPECT_EQ(g.where(Vec<2>(2.15, 1.95), key, xi), Where::Window);
  EXPECT_EQ(g.where(Vec<2>(3.05, 1.05), key, xi), Where::OutsideWindow);
}

// Keys follow the dense window's cell order (slab axis slowest), so particles sort the same;
// a cell's corners are distinct nodes, and neighbouring cells share the nodes of their face.
TEST(SparseGrid, KeysInDenseOrderAndSharedCorners) {
  const Lattice lat = lattice3(20, 0.5);
  SparseGrid<3> g(lat, BoundarySpec{});
  UniformGrid<3> dense(lat, BoundarySpec{});
  std::vector<Vec3> x;
  for (int i = 0; i < 200; ++i)  // a scattered handful along a helix
    x.push_back(Vec3(5 + 3 * std::cos(0.3 * i), 5 + 2 * std::sin(0.3 * i), 1 + 0.04 * i));
  g.fit(x.data(), x.size());
  dense.fit(x.data(), x.size());
  EXPECT_EQ(g.slab_axis(), dense.slab_axis());
  EXPECT_EQ(g.layers(), dense.layers());
  for (std::size_t i = 0; i < x.size(); ++i)
    for (std::size_t j = 0; j < x.size(); ++j) {
      std::int64_t ki, kj, di, dj;
      Vec3 xi;
      g.locate(x[i], ki, xi);
      g.locate(x[j], kj, xi);
      dense.locate(x[i], di, xi);
      dense.locate(x[j], dj, xi);
      ASSERT_EQ(ki < kj, di < dj);
      ASSERT_EQ(g.layer(ki), dense.layer(di));
    }
  std::int64_t key = -1, nodes[8], next[8];
  Vec3 xi;
  ASSERT_EQ(g.where(x[100], key, xi), Where::Window);
  g.cell_nodes(key, nodes);
  EXPECT_EQ(std::set<std::int64_t>(nodes, nodes + 8).size(), 8u);
  std::int64_t key_x;
  ASSERT_EQ(g.where(x[100] + Vec3(0.5, 0, 0), key_x, xi), Where::Window);  // the cell on +x
  g.cell_nodes(key_x, next);
  for (int c = 0; c < 8; ++c)
    if (!(c & 1)) {
      EXPECT_EQ(next[c], nodes[c | 1]);  // its -x face is our +x face
    }
}

// Nodes on constrained faces: only the active ones, with the face they lie on.
TEST(SparseGrid, FaceNodesAreTheActiveOnes) {
  const Lattice lat = lattice3(30, 1.0);
  BoundarySpec b;
  b.face[4] = BoundaryType::Fixed;  // z_min
  b.face[0] = BoundaryType::Slip;   // x_min, never reached
  SparseGrid<3> g(lat, b);
  std::vector<Vec3> x{Vec3(10.5, 10.5, 0.5), Vec3(20.5, 20.5, 0.5)};
  g.fit(x.data(), x.size());
  EXPECT_EQ(g.fixed_nodes().size(), 2u * 16u);  // a 4 x 4 patch of nodes under each
  EXPECT_TRUE(g.slip_nodes().empty());
  for (const auto& f : g.fixed_nodes()) EXPECT_EQ(f.face, 4);
}

// The trilinear kernels ask "is x still in its bin's cell c?" as c <= (x - origin) / h < c + 1
// (CellLattice::in_cell) instead of locating it: the answer and the local coordinates must be
// locate's exactly, bit for bit, at random points and at points one rounding step either side of
// cell faces, where a fused multiply-add or a different order would show.
TEST(CellLattice, InCellIsLocateBitForBit) {
  Lattice lat = lattice3(60, 0.38e-3);  // Taylor-bar cells, an origin off the lattice of h
  lat.origin = Vec3(-5.43e-3, -5.41e-3, 1.7e-4);
  const UniformGrid<3> g(lat, BoundarySpec{});
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int points = 0, faces = 0, out = 0;
  auto check = [&](const Vec3& x) {
    IVec<3> cell;
    Vec3 xi_loc;
    g.CellLattice<3>::locate(x, cell, xi_loc);
    for (int dc = -1; dc <= 1; ++dc) {  // its own cell, and the neighbours along x
      const double c[3] = {double(cell[0] + dc), double(cell[1]), double(cell[2])};
      Vec3 xi;
      const bool in = g.in_cell(c, x, xi);
      EXPECT_EQ(in, dc == 0) << "x = " << x.transpose() << ", cell offset " << dc;
      if (dc == 0) {
        for (int a = 0; a < 3; ++a)
          EXPECT_EQ(std::bit_cast<std::uint64_t>(xi[a]), std::bit_cast<std::uint64_t>(xi_loc[a]));
      }
      out += !in;
    }
    ++points;
  };
  for (int k = 0; k < 20000; ++k) {
    Vec3 x;
    for (int a = 0; a < 3; ++a) x[a] = lat.origin[a] + lat.h * (1.0 + 58.0 * u(rng));
    check(x);
    // One and two rounding steps either side of the face below x along each axis.
    for (int a = 0; a < 3; ++a) {
      const double face = lat.origin[a] + lat.h * std::floor((x[a] - lat.origin[a]) / lat.h);
      Vec3 y = x;
      for (double p : {std::nextafter(std::nextafter(face, -1.0), -1.0), std::nextafter(face, -1.0),
                       face, std::nextafter(face, 1.0)}) {
        y[a] = p;
        check(y);
        ++faces;
      }
    }
  }
  EXPECT_EQ(points, 20000 + faces);
  EXPECT_EQ(out, 2 * points);  // each point in exactly one of the three cells tried
  const double nan_c[3] = {1, 1, 1};
  Vec3 xi;
  EXPECT_FALSE(g.in_cell(nan_c, Vec3(std::nan(""), 0, 0), xi));
}

}  // namespace
}  // namespace mpm
