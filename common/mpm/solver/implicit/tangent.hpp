#pragma once
/// The tangent preconditioner's factored matrix (ImplicitSolver::factor_tangent assembles it,
/// tangent.cpp), kept between steps while it still works.
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cstdint>
#include <vector>

namespace mpm {

struct TangentFactor {
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;  ///< velocity: M + theta dt^2 K_t
  Eigen::SparseLU<Eigen::SparseMatrix<double>> lu;          ///< momentum: I + theta dt^2 K_t W
  /// What the factor was built for: the unknowns (global node and component) and dt; and the
  /// Krylov iterations per Newton iteration of the first solve with it, and of the last.
  std::vector<std::int64_t> keys;
  double dt = 0, fresh_rate = -1, last_rate = 0;
  bool valid = false;
  /// The sparsity pattern the factor was analysed for: the ordering is reused while the
  /// pattern stays (the same unknowns, the particles in the same cells), only refactored.
  std::vector<int> outer, inner;
  /// Factors A (compressed here) with `solver`; false when it cannot be factored.
  template <class Solver>
  bool factor(Solver& solver, Eigen::SparseMatrix<double>& A) {
    A.makeCompressed();
    const int* o = A.outerIndexPtr();
    const int* in = A.innerIndexPtr();
    const bool same = outer.size() == std::size_t(A.outerSize() + 1) &&
                      inner.size() == std::size_t(A.nonZeros()) &&
                      std::equal(outer.begin(), outer.end(), o) &&
                      std::equal(inner.begin(), inner.end(), in);
    if (!same) {
      solver.analyzePattern(A);
      outer.assign(o, o + A.outerSize() + 1);
      inner.assign(in, in + A.nonZeros());
    }
    solver.factorize(A);
    if (solver.info() == Eigen::Success) return true;
    outer.clear();  // analyse again next time
    return false;
  }
};

}  // namespace mpm
