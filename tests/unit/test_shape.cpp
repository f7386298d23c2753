// Shape functions of the standard cell: partition of unity, gradients summing to zero,
// linear fields (values and gradients) reproduced exactly, in 2D and 3D.
#include <gtest/gtest.h>

#include <random>

#include "mpm/grid/shape.hpp"

namespace mpm {
namespace {

template <int D>
void check_cell(int samples) {
  std::mt19937 rng(42 + D);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double h = 0.37e-3, inv_h = 1.0 / h;
  // A linear field phi(x) = a + g.x on the cell [0,h]^D.
  Vec<D> g;
  for (int a = 0; a < D; ++a) g[a] = 3.0 * a - 1.7;
  const double a0 = 0.25;
  for (int s = 0; s < samples; ++s) {
    Vec<D> xi;
    for (int a = 0; a < D; ++a) xi[a] = u(rng);
    double N[kCorners<D>];
    Vec<D> G[kCorners<D>];
    shape_functions<D>(xi, inv_h, N, G);
    double sumN = 0, phi = 0;
    Vec<D> sumG = Vec<D>::Zero(), grad = Vec<D>::Zero();
    Mat<D> xG = Mat<D>::Zero();
    for (int c = 0; c < kCorners<D>; ++c) {
      Vec<D> xc;
      for (int a = 0; a < D; ++a) xc[a] = ((c >> a) & 1) * h;
      const double phic = a0 + g.dot(xc);
      EXPECT_GE(N[c], 0.0);
      sumN += N[c];
      sumG += G[c];
      phi += N[c] * phic;
      grad += phic * G[c];
      xG += xc * G[c].transpose();
    }
    const Vec<D> x = xi * h;
    EXPECT_NEAR(sumN, 1.0, 1e-14);                       // partition of unity
    EXPECT_LT(sumG.norm(), 1e-12 * inv_h);               // gradients sum to zero
    EXPECT_NEAR(phi, a0 + g.dot(x), 1e-13);              // linear field reproduced
    EXPECT_LT((grad - g).norm(), 1e-11 * g.norm());      // its gradient too
    EXPECT_LT((xG - Mat<D>::Identity()).norm(), 1e-12);  // sum x_c (x) G_c = I
    double Nv[kCorners<D>];
    shape_values<D>(xi, Nv);
    for (int c = 0; c < kCorners<D>; ++c) EXPECT_DOUBLE_EQ(Nv[c], N[c]);
  }
}

TEST(Shape, Trilinear) {
  check_cell<3>(2000);
}
TEST(Shape, Bilinear) {
  check_cell<2>(2000);
}

TEST(Shape, CornerValuesAreKronecker) {
  for (int k = 0; k < 8; ++k) {
    Vec3 xi(k & 1, (k >> 1) & 1, (k >> 2) & 1);
    double N[8];
    shape_values<3>(xi, N);
    for (int c = 0; c < 8; ++c) EXPECT_DOUBLE_EQ(N[c], c == k ? 1.0 : 0.0);
  }
}

}  // namespace
}  // namespace mpm
