// Matrix-free Newton-Krylov on small systems with known solutions: CG and GMRES against dense
// solves, the directional difference of (001, eq. 2.4.18) against an exact Jacobian, Newton's
// quadratic convergence, the line search on a problem where plain Newton diverges, and the
// Eisenstat-Walker forcing against a fixed tight one.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <random>

#include "mpm/solver/implicit/newton_krylov.hpp"

namespace mpm {
namespace {

using nk::Vector;

/// A symmetric positive definite matrix with a wide spread of diagonal scales: the 1D
/// Laplacian (stiffness) plus a diagonal "lumped mass" spanning four decades.
Eigen::MatrixXd spd(int n) {
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    A(i, i) = 2.0 + std::pow(10.0, 4.0 * i / (n - 1));
    if (i > 0) A(i, i - 1) = A(i - 1, i) = -1.0;
  }
  return A;
}

/// A non-symmetric matrix: 1D convection-diffusion (upwind), diagonally dominant.
Eigen::MatrixXd nonsymmetric(int n) {
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    A(i, i) = 4.0;
    if (i > 0) A(i, i - 1) = -2.5;
    if (i + 1 < n) A(i, i + 1) = -0.5;
  }
  return A;
}

nk::Operator apply(const Eigen::MatrixXd& A, int* count = nullptr) {
  return [&A, count](const Vector& x, Vector& y) {
    y = A * x;
    if (count) ++*count;
    return true;
  };
}

Vector random_vector(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  return Vector::NullaryExpr(n, [&](Eigen::Index) { return u(rng); });
}

TEST(Krylov, ConjugateGradientsSolveSpdSystem) {
  const int n = 40;
  const Eigen::MatrixXd A = spd(n);
  const Vector b = random_vector(n, 1), exact = A.ldlt().solve(b);
  Vector x;
  const nk::LinearReport plain = nk::cg(apply(A), b, x, 1e-10, 500, nullptr);
  ASSERT_TRUE(plain.converged);
  // ||r|| <= 1e-10 ||b|| bounds the error by cond(A) 1e-10 (cond ~ 1e4 here).
  EXPECT_LT((x - exact).norm(), 1e-5 * exact.norm());
  EXPECT_LT((b - A * x).norm(), 1e-10 * b.norm() * 1.0001);
  // The diagonal preconditioner removes the spread of the diagonal: far fewer iterations.
  const Vector inv_diag = A.diagonal().cwiseInverse();
  const nk::Preconditioner diag = nk::diagonal_preconditioner(inv_diag);
  const nk::LinearReport pre = nk::cg(apply(A), b, x, 1e-10, 500, &diag);
  ASSERT_TRUE(pre.converged);
  EXPECT_LT((x - exact).norm(), 1e-8 * exact.norm());
  EXPECT_LT(pre.iterations, plain.iterations / 2) << pre.iterations << " vs " << plain.iterations;
}

TEST(Krylov, GmresSolvesNonsymmetricSystem) {
  const int n = 30;
  const Eigen::MatrixXd A = nonsymmetric(n);
  const Vector b = random_vector(n, 2), exact = A.partialPivLu().solve(b);
  // A basis as large as the system: exact in at most n iterations (round-off aside).
  Vector x;
  int applications = 0;
  nk::LinearReport r = nk::gmres(apply(A, &applications), b, x, 1e-12, n, 0, nullptr);
  ASSERT_TRUE(r.converged);
  EXPECT_LE(r.iterations, n);
  EXPECT_EQ(r.iterations, applications);
  EXPECT_LT((x - exact).norm(), 1e-10 * exact.norm());
  // Its residual estimate |g_{k+1}| (001, Algorithm 4, step g) is the true residual.
  EXPECT_NEAR((b - A * x).norm() / b.norm(), r.relative_residual, 1e-12);
  // A small basis with restarts, right-preconditioned, reaches the same answer.
  const Vector inv_diag = A.diagonal().cwiseInverse();
  const nk::Preconditioner diag = nk::diagonal_preconditioner(inv_diag);
  r = nk::gmres(apply(A), b, x, 1e-12, 5, 50, &diag);
  ASSERT_TRUE(r.converged);
  EXPECT_LT((x - exact).norm(), 1e-10 * exact.norm());
  // One basis of 5 without restarts stops short but still reduces the residual.
  r = nk::gmres(apply(A), b, x, 1e-12, 5, 0, nullptr);
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.iterations, 5);
  EXPECT_LT((b - A * x).norm(), b.norm());
}

/// F(u) = A u + c u^3 - b (componentwise cube): smooth, J = A + 3 c diag(u^2).
class CubicSystem : public nk::NonlinearSystem {
 public:
  CubicSystem(Eigen::MatrixXd A, Vector b, double c) : A_(std::move(A)), b_(std::move(b)), c_(c) {}
  bool evaluate(const Vector& u, Vector& F) override {
    ++evaluations;
    F = A_ * u + c_ * u.array().cube().matrix() - b_;
    return true;
  }
  Eigen::MatrixXd jacobian(const Vector& u) const {
    Eigen::MatrixXd J = A_;
    J.diagonal() += 3 * c_ * u.array().square().matrix();
    return J;
  }
  long evaluations = 0;

 private:
  Eigen::MatrixXd A_;
  Vector b_;
  double c_;
};

TEST(Newton, DirectionalDifferenceMatchesTheJacobian) {
  const int n = 12;
  CubicSystem sys(spd(n), random_vector(n, 3), 0.5);
  const Vector u = random_vector(n, 4), s = random_vector(n, 5);
  Vector F, Js;
  sys.evaluate(u, F);
  long evals = 0;
  for (double h : {1e-4, 1e-5, 1e-6}) {
    ASSERT_TRUE(nk::directional_difference(sys, u, F, s, h, 0.0, Js, evals));
    const Vector exact = sys.jacobian(u) * s;
    // Forward difference: error ~ h ||u|| |F''| ||s||, here below 10 h relative.
    EXPECT_LT((Js - exact).norm(), 10 * h * exact.norm()) << "h = " << h;
  }
  // s = 0 gives 0 with no evaluation; u = 0 uses h itself as the step (eq. 2.4.18, third case).
  const long before = evals;
  ASSERT_TRUE(nk::directional_difference(sys, u, F, Vector::Zero(n), 1e-5, 0.0, Js, evals));
  EXPECT_EQ(Js.norm(), 0.0);
  EXPECT_EQ(evals, before);
  Vector F0;
  sys.evaluate(Vector::Zero(n), F0);
  ASSERT_TRUE(nk::directional_difference(sys, Vector::Zero(n), F0, s, 1e-5, 0.0, Js, evals));
  EXPECT_LT((Js - sys.jacobian(Vector::Zero(n)) * s).norm(), 1e-4 * Js.norm());
}

TEST(Newton, ConvergesQuadraticallyWithTightLinearSolves) {
  const int n = 20;
  CubicSystem sys(spd(n), 10 * random_vector(n, 6), 2.0);
  Vector u = Vector::Zero(n);
  nk::Settings S;
  S.krylov = KrylovMethod::GMRES;
  S.gmres_basis = n;
  S.linear_tolerance = 1e-12;
  S.newton_tolerance = 1e-10;
  S.derivative_step = 1e-7;
  const nk::Report r = nk::solve(sys, u, S, nullptr, 0.0);
  ASSERT_TRUE(r.converged()) << nk::to_string(r.outcome);
  Vector F;
  sys.evaluate(u, F);
  EXPECT_LT(F.norm(), 1e-10);
  // q-quadratic near the root (eq. 2.4.17): the order log(r_k / r_{k-1}) / log(r_{k-1} /
  // r_{k-2}) of the last three residuals is about 2 (a first-order method gives 1).
  const auto& res = r.residuals;
  ASSERT_GE(res.size(), 4u);
  const std::size_t k = res.size() - 1;
  const double order = std::log(res[k] / res[k - 1]) / std::log(res[k - 1] / res[k - 2]);
  EXPECT_GT(order, 1.6);
}

/// F(u) = atan(u): Newton from |u0| > 1.39 overshoots further every step; backtracking
/// (001, section 3.2.3) brings it home.
class Arctan : public nk::NonlinearSystem {
 public:
  bool evaluate(const Vector& u, Vector& F) override {
    F = u.array().atan().matrix();
    return true;
  }
};

TEST(Newton, LineSearchRescuesNewtonFarFromTheRoot) {
  Arctan sys;
  nk::Settings S;
  S.krylov = KrylovMethod::GMRES;
  S.gmres_basis = 1;
  S.linear_tolerance = 1e-12;
  S.newton_tolerance = 1e-12;
  Vector u = Vector::Constant(1, 10.0);
  const nk::Report r = nk::solve(sys, u, S, nullptr, 0.0);
  ASSERT_TRUE(r.converged()) << nk::to_string(r.outcome);
  EXPECT_NEAR(u[0], 0.0, 1e-11);
  EXPECT_GT(r.work.line_search_cuts, 0);
  // Without the line search the first full Newton step (u - (1 + u^2) atan(u)) diverges.
  S.max_line_search = 0;
  u = Vector::Constant(1, 10.0);
  EXPECT_EQ(nk::solve(sys, u, S, nullptr, 0.0).outcome, nk::Outcome::NoDescent);
}

TEST(Newton, InadmissibleStartIsReported) {
  class Never : public nk::NonlinearSystem {
    bool evaluate(const Vector&, Vector&) override { return false; }
  } sys;
  Vector u = Vector::Zero(3);
  EXPECT_EQ(nk::solve(sys, u, nk::Settings{}, nullptr, 0.0).outcome,
            nk::Outcome::InadmissibleStart);
}

TEST(Newton, EisenstatWalkerSavesKrylovIterations) {
  // A mildly nonlinear system from a good initial guess, with a loose Newton tolerance: fixed
  // tight forcing over-solves every linear system; Eisenstat-Walker does not.
  const int n = 60;
  const Eigen::MatrixXd A = spd(n) + 0.3 * nonsymmetric(n);
  const Vector b = random_vector(n, 7);
  auto run = [&](Forcing f) {
    CubicSystem sys(A, b, 0.05);
    Vector u = A.partialPivLu().solve(b);  // the root of the linear part
    nk::Settings S;
    S.krylov = KrylovMethod::GMRES;
    S.gmres_basis = n;
    S.linear_tolerance = 1e-8;
    S.newton_tolerance = 1e-6;
    S.forcing = f;
    const nk::Report r = nk::solve(sys, u, S, nullptr, 0.0);
    EXPECT_TRUE(r.converged());
    return r.work.krylov;
  };
  const long fixed = run(Forcing::Fixed), ew = run(Forcing::EisenstatWalker);
  EXPECT_LT(ew, fixed) << "EW " << ew << " vs fixed " << fixed;
}

}  // namespace
}  // namespace mpm
