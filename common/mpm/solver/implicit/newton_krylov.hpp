#pragma once
/// Matrix-free Newton-Krylov (001, section 2.4; Kelley 1995): Newton's method (Algorithm 1)
/// whose linear systems J s = -F are solved by conjugate gradients (Algorithm 3) or GMRES
/// (Algorithm 4), with the Jacobian applied as the directional difference of eq. 2.4.18, a
/// backtracking line search (section 3.2.3), fixed or Eisenstat-Walker forcing terms and an
/// optional preconditioner. Nothing here knows about MPM: a NonlinearSystem supplies
/// F(u), and the small dense parts (the GMRES Hessenberg least squares) use Eigen.
#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "mpm/scene/scene.hpp"

namespace mpm::nk {

using Vector = Eigen::VectorXd;

/// F(u) = 0, evaluated without a matrix. The residual is expected to be dimensionless (the
/// tolerances are absolute on ||F||_2); the unknowns may carry units.
class NonlinearSystem {
 public:
  virtual ~NonlinearSystem() = default;
  /// F(u) into F (resized by the caller to u's size). Returns false when u is inadmissible
  /// (e.g. it folds the grid or inverts a material volume); F is then undefined.
  virtual bool evaluate(const Vector& u, Vector& F) = 0;
  /// Keeps whatever state the last evaluate() produced as that of the current iterate (a
  /// system that carries trial state, e.g. updated stresses, swaps it in here).
  virtual void accept() {}
};

/// A linear operator y = A x; returns false when it cannot be applied at x.
using Operator = std::function<bool(const Vector& x, Vector& y)>;

/// z = P^-1 r, an approximate inverse of the Jacobian: applied on the right in GMRES; for CG
/// it must be symmetric positive definite.
using Preconditioner = std::function<void(const Vector& r, Vector& z)>;
/// The preconditioner of a diagonal, given as its inverse (kept by reference).
Preconditioner diagonal_preconditioner(const Vector& inv_diag);

/// How a Krylov solve ended.
struct LinearReport {
  int iterations = 0;              ///< operator applications
  double relative_residual = 1.0;  ///< ||b - A x|| / ||b|| (GMRES: its estimate)
  bool converged = false;
  bool failed = false;  ///< the operator could not be applied, or CG broke down
};

/// Preconditioned conjugate gradients for A x = b from x = 0 (001, Algorithm 3). `P` (may be
/// null) is the preconditioner. Stops when
/// ||r|| <= rtol ||b||, after max_it iterations, or on a non-positive curvature p.Ap (the
/// iterate so far is kept).
LinearReport cg(const Operator& A, const Vector& b, Vector& x, double rtol, int max_it,
                const Preconditioner* P);

/// GMRES for A x = b from x = 0 (001, Algorithm 4: Arnoldi with modified Gram-Schmidt, Givens
/// rotations), right-preconditioned by `P` (may be null), a basis of
/// `basis` vectors, restarted `restarts` times at most.
LinearReport gmres(const Operator& A, const Vector& b, Vector& x, double rtol, int basis,
                   int restarts, const Preconditioner* P);

/// Newton-Krylov settings, taken from the scene's ImplicitSpec.
struct Settings {
  double newton_tolerance = 1e-5;  ///< converged when ||F||_2 <= this
  double linear_tolerance = 1e-3;  ///< eta of the fixed forcing; floor of Eisenstat-Walker
  double derivative_step = 1e-5;   ///< h of (001, eq. 2.4.18)
  KrylovMethod krylov = KrylovMethod::GMRES;
  int gmres_basis = 20;
  int gmres_restarts = 0;
  int max_krylov = 200;  ///< CG iterations per Newton step
  int max_newton = 25;
  int max_line_search = 8;  ///< halvings of the Newton step
  Forcing forcing = Forcing::Fixed;
  double eta_max = 0.5;   ///< Eisenstat-Walker: largest forcing term (Kelley: 0.9;
                          ///< 0.5 measured better on the V7 upsetting, equal elsewhere)
  double ew_gamma = 0.9;  ///< Eisenstat-Walker: gamma of choice 2
  double armijo = 1e-4;   ///< sufficient decrease: ||F_new|| <= (1 - armijo lambda) ||F||
};

/// Work done, summed over calls.
struct Counters {
  long newton = 0;            ///< Newton iterations (linear solves)
  long krylov = 0;            ///< Krylov iterations (Jacobian products)
  long evaluations = 0;       ///< residual evaluations, Jacobian products included
  long line_search_cuts = 0;  ///< halvings of Newton steps
  Counters& operator+=(const Counters& o) {
    newton += o.newton;
    krylov += o.krylov;
    evaluations += o.evaluations;
    line_search_cuts += o.line_search_cuts;
    return *this;
  }
};

enum class Outcome {
  Converged,
  InadmissibleStart,  ///< F could not be evaluated at the initial guess
  NoDescent,          ///< the line search found no acceptable point
  TooManyIterations,  ///< max_newton reached
  ZeroStep,           ///< the Krylov solve gave no step
};
std::string to_string(Outcome o);

struct Report {
  Outcome outcome = Outcome::TooManyIterations;
  std::vector<double> residuals;  ///< ||F||_2 at each Newton iterate, the first included
  Counters work;
  bool converged() const { return outcome == Outcome::Converged; }
};

/// The directional difference D_h F(u, s) of (001, eq. 2.4.18), with a safeguard: the
/// perturbation is h max(||u||, u_typ) (Kelley 1995, section 5.2: a typical size of u keeps
/// it from vanishing when u is small; u_typ = 0 gives the seed's formula). F_u = F(u).
/// Returns false when F cannot be evaluated at the perturbed point (forward and backward).
bool directional_difference(NonlinearSystem& system, const Vector& u, const Vector& F_u,
                            const Vector& s, double h, double u_typ, Vector& Js, long& evaluations);

/// Solves F(u) = 0 from the initial guess u (overwritten by the last accepted iterate).
/// `P` (may be null) is the Krylov solves' preconditioner; u_typ the typical size of ||u|| for
/// the directional difference.
Report solve(NonlinearSystem& system, Vector& u, const Settings& settings, const Preconditioner* P,
             double u_typ);

}  // namespace mpm::nk
