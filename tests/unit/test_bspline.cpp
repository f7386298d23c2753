// The quadratic B-spline grid (grid.shape = "bspline"): the weights' identities that APIC's
// proofs use, and the grid's stencils, window and ghost nodes.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "mpm/grid/bspline_grid.hpp"

namespace mpm {
namespace {

// Partition of unity, linear fields reproduced (sum N (x_i - x_p) = 0, sum x_i grad N^T = I),
// gradients summing to zero, and D_p = sum N (x_i - x_p)(x_i - x_p)^T = h^2 / 4 I at every
// point (Jiang et al. 2015: what makes APIC's C_p = B_p D_p^-1 a constant scaling).
template <int D>
void check_identities(int samples) {
  std::mt19937 rng(7 + D);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double h = 0.37e-3;
  BsplineGrid<D> grid(Lattice{D, Vec3::Zero(), h, {8, 8, D == 3 ? 8 : 1}}, BoundarySpec{});
  for (int s = 0; s < samples; ++s) {
    Vec<D> xi;
    for (int a = 0; a < D; ++a) xi[a] = u(rng);
    double N[kBsplineNodes<D>];
    Vec<D> G[kBsplineNodes<D>], d[kBsplineNodes<D>], W[kBsplineNodes<D>];
    grid.shape(0, xi, N, G);
    grid.offsets(0, xi, d);
    grid.affine_weights(0, xi, N, G, W);
    double sumN = 0;
    Vec<D> first = Vec<D>::Zero(), sumG = Vec<D>::Zero();
    Mat<D> second = Mat<D>::Zero(), xG = Mat<D>::Zero(), dW = Mat<D>::Zero();
    for (int c = 0; c < kBsplineNodes<D>; ++c) {
      EXPECT_GE(N[c], 0.0);
      sumN += N[c];
      first += N[c] * d[c];
      second += N[c] * d[c] * d[c].transpose();
      sumG += G[c];
      xG += (h * d[c]) * G[c].transpose();
      dW += (h * d[c]) * W[c].transpose();  // an affine field x -> A x gives C = A
    }
    EXPECT_NEAR(sumN, 1.0, 1e-14);
    EXPECT_LT(first.norm(), 1e-14);
    EXPECT_LT((second - 0.25 * Mat<D>::Identity()).norm(), 1e-14);
    EXPECT_LT(sumG.norm() * h, 1e-13);
    EXPECT_LT((xG - Mat<D>::Identity()).norm(), 1e-13);
    EXPECT_LT((dW - Mat<D>::Identity()).norm(), 1e-13);
  }
}

TEST(Bspline, WeightsReproduceLinearFieldsAndGiveAConstantInertia2D) {
  check_identities<2>(200);
}
TEST(Bspline, WeightsReproduceLinearFieldsAndGiveAConstantInertia3D) {
  check_identities<3>(200);
}

// The weights are continuous as a point crosses from one stencil to the next (at xi = 1 of one
// and xi = 0 of the next, the shared nodes carry the same weight and gradient).
TEST(Bspline, WeightsAndGradientsAreContinuousAcrossStencils) {
  double w0[3], dw0[3], w1[3], dw1[3];
  bspline_1d(1.0, w0, dw0);  // the end of a stencil based at node b ...
  bspline_1d(0.0, w1, dw1);  // ... the start of the one based at b + 1
  EXPECT_EQ(w0[0], 0.0);
  EXPECT_EQ(dw0[0], 0.0);
  for (int k = 0; k < 2; ++k) {
    EXPECT_DOUBLE_EQ(w0[k + 1], w1[k]);
    EXPECT_DOUBLE_EQ(dw0[k + 1], dw1[k]);
  }
  EXPECT_EQ(w1[2], 0.0);
  EXPECT_EQ(dw1[2], 0.0);
}

// A particle within half a cell of the domain's edge reaches the ghost node outside; a
// constrained face holds its own node plane, and the ghost plane beyond it mirrors the plane as
// far inside; a point outside the domain is reported so even though the widened lattice would
// hold it.
TEST(Bspline, GhostNodesBeyondTheFacesMirrorTheNodesInside) {
  BoundarySpec b;
  b.face[0] = BoundaryType::Fixed;  // x_min
  b.face[3] = BoundaryType::Slip;   // y_max
  const double h = 1e-3;
  BsplineGrid<2> grid(Lattice{2, Vec3::Zero(), h, {4, 4, 1}}, b);
  const Vec<2> x[2] = {Vec<2>(0.2e-3, 0.2e-3), Vec<2>(3.9e-3, 3.9e-3)};
  grid.fit(x, 2);
  std::int64_t key, nodes[9];
  Vec<2> xi;
  ASSERT_EQ(grid.where(x[0], key, xi), Where::Window);
  EXPECT_NEAR(xi[0], 0.7, 1e-12);  // 0.2 cells from node 0: 0.7 past the ghost midpoint
  grid.cell_nodes(key, nodes);
  // Its stencil starts at the ghost node (-1, -1): global node 0 of the widened lattice.
  EXPECT_EQ(grid.global_node(nodes[0]), IVec<2>(0, 0));
  EXPECT_EQ(grid.global_node(nodes[8]), IVec<2>(2, 2));
  // Held: fixed x_min is the widened lattice's node plane 1, slip y_max its plane 5.
  for (const auto& f : grid.fixed_nodes()) EXPECT_EQ(grid.global_node(f.node)[0], 1);
  for (const auto& f : grid.slip_nodes()) EXPECT_EQ(grid.global_node(f.node)[1], 5);
  EXPECT_EQ(grid.fixed_nodes().size(), 7u);
  EXPECT_EQ(grid.slip_nodes().size(), 7u);
  // Ghosts: x plane 0 mirrors plane 2 (every component), y plane 6 mirrors plane 4 (y only).
  int xs = 0, ys = 0;
  for (const auto& g : grid.ghost_nodes()) {
    const IVec<2> n = grid.global_node(g.node), m = grid.global_node(g.mirror);
    if (g.face == 0) {
      ++xs;
      EXPECT_EQ(n[0], 0);
      EXPECT_EQ(m, IVec<2>(2, n[1]));
      EXPECT_EQ(grid.reflect(g, Vec<2>(1, 2)), Vec<2>(-1, -2));
    } else {
      ++ys;
      EXPECT_EQ(n[1], 6);
      EXPECT_EQ(m, IVec<2>(n[0], 4));
      EXPECT_EQ(grid.reflect(g, Vec<2>(1, 2)), Vec<2>(1, -2));
    }
  }
  EXPECT_EQ(xs, 7);
  EXPECT_EQ(ys, 7);
  EXPECT_EQ(grid.where(Vec<2>(-0.1e-3, 1e-3), key, xi), Where::OutsideDomain);
  EXPECT_EQ(grid.where(Vec<2>(1e-3, 4.1e-3), key, xi), Where::OutsideDomain);
}

}  // namespace
}  // namespace mpm
