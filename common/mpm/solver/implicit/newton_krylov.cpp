// Matrix-free Newton-Krylov: CG, GMRES, the directional difference and Newton with a
// backtracking line search (001, section 2.4 and 3.2.3; Kelley 1995).
#include "mpm/solver/implicit/newton_krylov.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace mpm::nk {

std::string to_string(Outcome o) {
  switch (o) {
    case Outcome::Converged:
      return "converged";
    case Outcome::InadmissibleStart:
      return "the initial guess is inadmissible (folded grid or inverted volume)";
    case Outcome::NoDescent:
      return "the line search found no decrease of the residual";
    case Outcome::TooManyIterations:
      return "too many Newton iterations";
    case Outcome::ZeroStep:
      return "the Krylov solve gave no step";
  }
  return "?";
}

// ------------------------------------------------------------------------------------------
// Conjugate gradients (001, Algorithm 3), preconditioned.

namespace {
/// A Krylov solve's start: x = 0 (n unknowns), which solves it when ||b|| = 0 (then true,
/// the report converged).
bool starts_solved(double b_norm, Vector& x, Eigen::Index n, LinearReport& rep) {
  x.setZero(n);
  if (b_norm != 0) return false;
  rep.converged = true;
  rep.relative_residual = 0;
  return true;
}
}  // namespace

Preconditioner diagonal_preconditioner(const Vector& inv_diag) {
  return [&inv_diag](const Vector& r, Vector& z) { z = inv_diag.cwiseProduct(r); };
}

LinearReport cg(const Operator& A, const Vector& b, Vector& x, double rtol, int max_it,
                const Preconditioner* P) {
  LinearReport rep;
  const Eigen::Index n = b.size();
  const double b_norm = b.norm();
  if (starts_solved(b_norm, x, n, rep)) return rep;
  Vector r = b;  // r_0 = b - A 0
  Vector z = r;
  if (P) (*P)(r, z);
  Vector p = z, w(n);
  double rho = r.dot(z);
  for (int k = 0; k < max_it; ++k) {
    rep.relative_residual = r.norm() / b_norm;
    if (rep.relative_residual <= rtol) {
      rep.converged = true;
      return rep;
    }
    ++rep.iterations;
    if (!A(p, w)) {  // (a) w_k = D_h F(v_n, p_k)
      rep.failed = true;
      return rep;
    }
    const double pw = p.dot(w);
    if (!(pw > 0)) {  // not positive definite along p: keep the iterate so far
      rep.failed = k == 0;
      return rep;
    }
    const double alpha = rho / pw;  // (b)
    x.noalias() += alpha * p;       // (c)
    r.noalias() -= alpha * w;       // (d)
    if (P)
      (*P)(r, z);
    else
      z = r;
    const double rho_new = r.dot(z);    // (e)
    const double beta = rho_new / rho;  // (f)
    p = z + beta * p;                   // (g)
    rho = rho_new;
  }
  rep.relative_residual = r.norm() / b_norm;
  rep.converged = rep.relative_residual <= rtol;
  return rep;
}

// ------------------------------------------------------------------------------------------
// GMRES (001, Algorithm 4), right-preconditioned: A P^-1 y = b, x = P^-1 y.

LinearReport gmres(const Operator& A, const Vector& b, Vector& x, double rtol, int basis,
                   int restarts, const Preconditioner* P) {
  LinearReport rep;
  const Eigen::Index n = b.size();
  const double b_norm = b.norm();
  if (starts_solved(b_norm, x, n, rep)) return rep;
  const int m = std::max(1, basis);
  Eigen::MatrixXd V(n, m + 1);  // orthonormal basis p_1 .. p_{k+1}
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(m + 1, m);
  Eigen::VectorXd cs(m), sn(m), g(m + 1);
  Vector r = b, w(n), z(n);
  auto precondition = [&](const Vector& v) -> Vector {
    if (!P) return v;
    Vector pv(v.size());
    (*P)(v, pv);
    return pv;
  };
  for (int cycle = 0; cycle <= restarts; ++cycle) {
    if (cycle > 0) {  // r = b - A x for the restart
      ++rep.iterations;
      if (!A(x, w)) {
        rep.failed = true;
        return rep;
      }
      r = b - w;
    }
    const double beta = r.norm();
    rep.relative_residual = beta / b_norm;
    if (rep.relative_residual <= rtol) {
      rep.converged = true;
      return rep;
    }
    V.col(0) = r / beta;  // Step 1: p_1 = r_0 / ||r_0||, beta e_1
    g.setZero();
    g[0] = beta;
    H.setZero();
    int k = 0;
    for (int j = 0; j < m; ++j) {
      ++rep.iterations;
      z = precondition(V.col(j));
      if (!A(z, w)) {  // (a) p_{k+1} = D_h F(v_n, p_k)
        if (j == 0) {
          rep.failed = true;
          return rep;
        }
        break;  // use the basis built so far
      }
      for (int i = 0; i <= j; ++i) {  // (b) modified Gram-Schmidt
        H(i, j) = w.dot(V.col(i));
        w.noalias() -= H(i, j) * V.col(i);
      }
      H(j + 1, j) = w.norm();                               // (c)
      if (H(j + 1, j) > 0) V.col(j + 1) = w / H(j + 1, j);  // (d)
      for (int i = 0; i < j; ++i) {                         // (e) previous rotations
        const double t = cs[i] * H(i, j) + sn[i] * H(i + 1, j);
        H(i + 1, j) = -sn[i] * H(i, j) + cs[i] * H(i + 1, j);
        H(i, j) = t;
      }
      const double a = H(j, j), c = H(j + 1, j);  // (f) new rotation
      const double d = std::hypot(a, c);
      cs[j] = d > 0 ? a / d : 1.0;
      sn[j] = d > 0 ? c / d : 0.0;
      H(j, j) = d;
      H(j + 1, j) = 0;
      g[j + 1] = -sn[j] * g[j];  // (g) rotate beta e_1
      g[j] = cs[j] * g[j];
      k = j + 1;
      rep.relative_residual = std::abs(g[j + 1]) / b_norm;
      if (rep.relative_residual <= rtol || c == 0) break;
    }
    if (k == 0) break;
    // Step 3: solve the k x k triangular system R y = g; Step 4: x += P^-1 V y.
    const Eigen::VectorXd y = H.topLeftCorner(k, k).triangularView<Eigen::Upper>().solve(g.head(k));
    x += precondition(V.leftCols(k) * y);
    if (rep.relative_residual <= rtol) {
      rep.converged = true;
      return rep;
    }
  }
  return rep;
}

// ------------------------------------------------------------------------------------------
// Newton's method (001, Algorithm 1) with the directional difference and a line search.

bool directional_difference(NonlinearSystem& system, const Vector& u, const Vector& F_u,
                            const Vector& s, double h, double u_typ, Vector& Js,
                            long& evaluations) {
  const double s_norm = s.norm();
  Js.setZero(F_u.size());
  if (s_norm == 0) return true;                  // (001, eq. 2.4.18), s = 0
  double sigma = h * std::max(u.norm(), u_typ);  // h ||v||, or h when v = 0
  if (!(sigma > 0)) sigma = h;
  Vector F_p(F_u.size());
  ++evaluations;
  if (system.evaluate(u + (sigma / s_norm) * s, F_p)) {
    Js = (s_norm / sigma) * (F_p - F_u);
    return true;
  }
  // Forward point inadmissible (e.g. it would fold the grid): try the backward difference.
  ++evaluations;
  if (system.evaluate(u - (sigma / s_norm) * s, F_p)) {
    Js = (s_norm / sigma) * (F_u - F_p);
    return true;
  }
  return false;
}

Report solve(NonlinearSystem& system, Vector& u, const Settings& S, const Preconditioner* P,
             double u_typ) {
  Report rep;
  Vector F(u.size()), F_trial(u.size()), s(u.size()), u_trial(u.size());
  ++rep.work.evaluations;
  if (!system.evaluate(u, F)) {
    rep.outcome = Outcome::InadmissibleStart;
    return rep;
  }
  system.accept();
  double f_norm = F.norm(), f_prev = f_norm;
  rep.residuals.push_back(f_norm);
  double eta = S.forcing == Forcing::EisenstatWalker ? S.eta_max : S.linear_tolerance;
  const Operator J = [&](const Vector& x, Vector& y) {
    return directional_difference(system, u, F, x, S.derivative_step, u_typ, y,
                                  rep.work.evaluations);
  };
  for (int it = 0;; ++it) {
    if (f_norm <= S.newton_tolerance) {  // Step 2: ||F(v_n)|| below the tolerance
      rep.outcome = Outcome::Converged;
      return rep;
    }
    if (it == S.max_newton) {
      rep.outcome = Outcome::TooManyIterations;
      return rep;
    }
    // Forcing term: fixed, or Eisenstat-Walker choice 2 with Kelley's safeguards. The first
    // term is the fixed one, raised to 0.5 tol / ||F|| so that a good initial guess is not
    // over-solved (the same floor applies to every later term).
    if (S.forcing == Forcing::EisenstatWalker) {
      double e = S.linear_tolerance;
      if (it > 0) {
        e = S.ew_gamma * (f_norm / f_prev) * (f_norm / f_prev);
        if (S.ew_gamma * eta * eta > 0.1) e = std::max(e, S.ew_gamma * eta * eta);
      }
      eta = std::min(S.eta_max, std::max(e, 0.5 * S.newton_tolerance / f_norm));
    }
    // Steps 3-4: J(v_n) s = -F(v_n), matrix-free (001, eq. 2.4.19).
    ++rep.work.newton;
    const Vector b = -F;
    const LinearReport lin = S.krylov == KrylovMethod::CG
                                 ? cg(J, b, s, eta, S.max_krylov, P)
                                 : gmres(J, b, s, eta, S.gmres_basis, S.gmres_restarts, P);
    rep.work.krylov += lin.iterations;
    if (!(s.squaredNorm() > 0) || !s.allFinite()) {
      rep.outcome = Outcome::ZeroStep;
      return rep;
    }
    // Step 5 with backtracking (001, section 3.2.3): halve the step until ||F|| decreases.
    double lambda = 1.0;
    for (int cut = 0;; ++cut) {
      u_trial = u + lambda * s;
      ++rep.work.evaluations;
      const bool ok = system.evaluate(u_trial, F_trial);
      if (ok && F_trial.norm() <= (1.0 - S.armijo * lambda) * f_norm) break;
      if (cut == S.max_line_search) {
        rep.outcome = Outcome::NoDescent;
        return rep;
      }
      lambda *= 0.5;
      ++rep.work.line_search_cuts;
    }
    system.accept();
    u = u_trial;
    F = F_trial;
    f_prev = f_norm;
    f_norm = F.norm();
    rep.residuals.push_back(f_norm);
  }
}

}  // namespace mpm::nk
