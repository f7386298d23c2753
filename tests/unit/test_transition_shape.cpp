// Shape functions of the transition cells of graded grids (004, section 3.1, eqs. 15-22):
// partition of unity, the Kronecker property, linear completeness (values and gradients) for
// every combination of optional nodes a grid can produce, the seed's own formulas, and
// non-negativity of the cell types a graded grid builds.
#include <gtest/gtest.h>

#include <random>

#include "mpm/grid/transition_shape.hpp"

namespace mpm {
namespace {

// The faces' mid-edge nodes (0-based): a mid-face node is present only with the four mid-edge
// nodes of its face (they are corners of the finer cells across that face).
constexpr int kFaceEdges[6][4] = {{11, 15, 16, 19}, {9, 13, 17, 18}, {8, 12, 16, 17},
                                  {10, 14, 18, 19}, {8, 9, 10, 11},  {12, 13, 14, 15}};

/// Masks of 3D transition cells a grid can produce: every face present only with its edges.
std::vector<std::uint32_t> closed_masks_3d() {
  std::vector<std::uint32_t> out;
  for (std::uint32_t m = 0; m < (1u << 18); ++m) {
    bool ok = true;
    for (int f = 0; f < 6 && ok; ++f)
      if ((m >> (12 + f)) & 1u)
        for (int e : kFaceEdges[f]) ok = ok && ((m >> (e - 8)) & 1u);
    if (ok) out.push_back(m);
  }
  return out;
}

/// Reference position p_k in [-1, 1]^D of the node output at index q for a mask.
template <int D>
std::vector<Vec<D>> node_positions(std::uint32_t mask) {
  const auto& T = kTransition<D>;
  std::vector<Vec<D>> x(kCorners<D>);
  for (int k = 0; k < kCorners<D>; ++k)
    for (int a = 0; a < D; ++a) x[T.corner_bits[k]][a] = T.p[k][a];
  for (int j = 0; j < kOptionalNodes<D>; ++j)
    if ((mask >> j) & 1u) {
      Vec<D> p;
      for (int a = 0; a < D; ++a) p[a] = T.p[kCorners<D> + j][a];
      x.push_back(p);
    }
  return x;
}

// Partition of unity, gradients summing to zero, linear fields (values and gradients)
// reproduced exactly, N_k(x_j) = delta_kj: at the 3^D sub-cell corners (where the piecewise
// multilinear functions are determined) and at random points, for every mask.
// Tolerance 1e-13: a few hundred operations on O(1) numbers in double precision.
template <int D>
void check_mask(std::uint32_t mask, std::mt19937& rng, int random_points) {
  const double h = 0.25e-3, inv_h = 1.0 / h;
  const std::vector<Vec<D>> p = node_positions<D>(mask);
  const int n = int(p.size());
  // Nodes in metres, cell [0, h]^D: x = (p + 1) h / 2.
  std::vector<Vec<D>> x(n);
  for (int k = 0; k < n; ++k) x[k] = 0.5 * h * (p[k] + Vec<D>::Ones());
  Vec<D> g;  // a linear field phi = 0.3 + g.x
  for (int a = 0; a < D; ++a) g[a] = 1.0 + 2.5 * a;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  auto check_at = [&](const Vec<D>& xi) {
    double N[kTransitionNodes<D>];
    Vec<D> G[kTransitionNodes<D>];
    ASSERT_EQ(transition_shape<D>(mask, xi, inv_h, N, G), n);
    double sum = 0, phi = 0;
    Vec<D> sumG = Vec<D>::Zero(), grad = Vec<D>::Zero(), xx = Vec<D>::Zero();
    Mat<D> xG = Mat<D>::Zero();
    for (int k = 0; k < n; ++k) {
      sum += N[k];
      sumG += G[k];
      const double phik = 0.3 + g.dot(x[k]);
      phi += N[k] * phik;
      grad += phik * G[k];
      xx += N[k] * x[k];
      xG += x[k] * G[k].transpose();
    }
    const Vec<D> at = h * xi;
    EXPECT_NEAR(sum, 1.0, 1e-13) << "mask " << mask;
    EXPECT_LT(sumG.norm() * h, 1e-12) << "mask " << mask;
    EXPECT_NEAR(phi, 0.3 + g.dot(at), 1e-13 * (1 + g.norm() * h)) << "mask " << mask;
    EXPECT_LT((grad - g).norm(), 1e-11 * g.norm()) << "mask " << mask;
    EXPECT_LT((xx - at).norm(), 1e-13 * h) << "mask " << mask;
    EXPECT_LT((xG - Mat<D>::Identity()).norm(), 1e-12) << "mask " << mask;
  };
  // Sub-cell corners, including every node: Kronecker there.
  int idx[D] = {};
  while (true) {
    Vec<D> xi;
    for (int a = 0; a < D; ++a) xi[a] = 0.5 * idx[a];
    check_at(xi);
    double N[kTransitionNodes<D>];
    transition_shape<D>(mask, xi, inv_h, N, nullptr);
    for (int k = 0; k < n; ++k) {
      const bool at_node = ((p[k] + Vec<D>::Ones()) * 0.5 - xi).norm() < 1e-14;
      if (!at_node) continue;
      EXPECT_NEAR(N[k], 1.0, 1e-14) << "mask " << mask << " node " << k;
      for (int j = 0; j < n; ++j) {
        if (j != k) {
          EXPECT_NEAR(N[j], 0.0, 1e-14) << "mask " << mask;
        }
      }
    }
    int a = 0;
    while (a < D && ++idx[a] == 3) idx[a++] = 0;
    if (a == D) break;
  }
  for (int s = 0; s < random_points; ++s) {
    Vec<D> xi;
    for (int a = 0; a < D; ++a) xi[a] = u(rng);
    check_at(xi);
  }
}

TEST(TransitionShape, EveryQuadrilateralFiveToEightNodes) {
  std::mt19937 rng(7);
  for (std::uint32_t mask = 0; mask < 16; ++mask) check_mask<2>(mask, rng, 50);
}

TEST(TransitionShape, EveryHexahedronNineToTwentySixNodes) {
  std::mt19937 rng(11);
  const auto masks = closed_masks_3d();
  EXPECT_EQ(masks.size(), 6210u);
  for (std::uint32_t mask : masks) check_mask<3>(mask, rng, 2);
  // Masks a grid cannot make (a face without its edges) still sum to one.
  for (std::uint32_t mask : {1u << 12, (1u << 17) | 1u}) check_mask<3>(mask, rng, 4);
}

// The seed's formulas for its examples: the 5-node quadrilateral (004, eqs. 16-18, node 5 on
// the +xi edge) and the hexahedron with nodes 10 and 25 (004, eqs. 20-22).
TEST(TransitionShape, MatchesTheSeedsWorkedExamples) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int s = 0; s < 200; ++s) {
    const Vec<2> xi(u(rng), u(rng));
    const double x = 2 * xi[0] - 1, y = 2 * xi[1] - 1;
    double N[8];
    ASSERT_EQ(transition_shape<2>(1u, xi, 1.0, N, nullptr), 5);
    const double N5 = 0.5 * (1 + x) * (1 - std::abs(y));  // (004, eq. 16)
    EXPECT_NEAR(N[4], N5, 1e-15);
    EXPECT_NEAR(N[3], 0.25 * (1 + x) * (1 + y) - 0.5 * N5, 1e-15);  // corner (+,+), eq. 17
    EXPECT_NEAR(N[1], 0.25 * (1 + x) * (1 - y) - 0.5 * N5, 1e-15);  // corner (+,-), eq. 18
    EXPECT_NEAR(N[0], 0.25 * (1 - x) * (1 - y), 1e-15);             // untouched (eq. 15)
  }
  const std::uint32_t mask = (1u << (10 - 9)) | (1u << (25 - 9));
  for (int s = 0; s < 200; ++s) {
    const Vec3 xi(u(rng), u(rng), u(rng));
    const double x = 2 * xi[0] - 1, y = 2 * xi[1] - 1, z = 2 * xi[2] - 1;
    double N[26];
    ASSERT_EQ(transition_shape<3>(mask, xi, 1.0, N, nullptr), 10);
    const double N25 = 0.5 * (1 - std::abs(x)) * (1 - std::abs(y)) * (1 + z);        // eq. 20
    const double N10 = 0.25 * (1 - x) * (1 - std::abs(y)) * (1 + z) - 0.5 * N25;     // eq. 21
    const double N3 = 0.125 * (1 - x) * (1 - y) * (1 + z) - 0.5 * N10 - 0.25 * N25;  // eq. 22
    EXPECT_NEAR(N[8], N10, 1e-15);
    EXPECT_NEAR(N[9], N25, 1e-15);
    EXPECT_NEAR(N[4], N3, 1e-15);  // node 3 = (-,-,+) is grid corner 4 (bit z)
  }
}

// Non-negativity of the cell types a graded grid builds from level boxes: a coarse cell next
// to one box touches it across one face (that face and its four edges present), along one
// edge, or at a corner (no optional node); next to two boxes on opposite sides, two opposite
// faces. The functions are multilinear in each sub-cell, so their minimum over the cell is
// their minimum at the 3^D sub-cell corners, which transition_min_value evaluates exactly.
TEST(TransitionShape, NonNegativeInEveryCellTypeOfAGrid) {
  for (int e = 0; e < 4; ++e) EXPECT_GE(transition_min_value<2>(1u << e), 0.0);
  EXPECT_GE(transition_min_value<2>(0b0101u), 0.0);  // opposite edges
  EXPECT_LT(transition_min_value<2>(0b0011u), 0.0);  // a concave corner: the grid rejects it
  auto face = [](int f) {
    std::uint32_t m = 1u << (12 + f);
    for (int e : kFaceEdges[f]) m |= 1u << (e - 8);
    return m;
  };
  EXPECT_GE(transition_min_value<3>(0), 0.0);
  for (int e = 0; e < 12; ++e) EXPECT_GE(transition_min_value<3>(1u << e), 0.0) << "edge " << e;
  for (int f = 0; f < 6; ++f) EXPECT_GE(transition_min_value<3>(face(f)), 0.0) << "face " << f;
  for (int f = 0; f < 6; f += 2) EXPECT_GE(transition_min_value<3>(face(f) | face(f + 1)), 0.0);
  // Two faces sharing an edge (a concave corner of the refined region) go negative: the grid
  // builder refuses such boxes (GradedGrid tests).
  EXPECT_LT(transition_min_value<3>(face(0) | face(2)), 0.0);
  // And the minimum really is attained at the sub-cell corners: random points never go lower.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (std::uint32_t mask : {1u, face(4), face(0) | face(1)}) {
    const double lo = transition_min_value<3>(mask);
    for (int s = 0; s < 2000; ++s) {
      double N[26];
      const int n = transition_shape<3>(mask, Vec3(u(rng), u(rng), u(rng)), 1.0, N, nullptr);
      for (int k = 0; k < n; ++k) ASSERT_GE(N[k], lo - 1e-15);
    }
  }
}

}  // namespace
}  // namespace mpm
