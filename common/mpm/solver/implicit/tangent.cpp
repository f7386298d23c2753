// The tangent preconditioner of the implicit solver: the elastic-plastic tangent stiffness
// assembled from the particles at the step's start, factored, and reused while it works.
#include "mpm/solver/implicit/tangent.hpp"

#include <algorithm>
#include <cmath>

#include "mpm/solver/implicit/implicit_solver.hpp"

namespace mpm {

namespace {

using Mat6 = Eigen::Matrix<double, 6, 6>;
/// Strain (Voigt xx yy zz yz xz xy, shears doubled) per nodal velocity component.
template <int D>
using StrainMatrix = Eigen::Matrix<double, 6, D>;

/// The tangent moduli of particle i in its state at t^k (Voigt, shears doubled): the elastic
/// ones, less the plastic part on the yield surface, C_ep = C - 6 G^2 / (3 G + H) n n^T with
/// n = s / |s| and H the hardening slope of the flow stress; a failed particle keeps only its
/// bulk modulus.
template <int D>
Mat6 tangent_moduli(const Material& mat, const ParticleView<D>& p, std::uint32_t i) {
  const bool failed = p.failed && p.failed[i];
  const double G = failed ? 0.0 : mat.shear_modulus(), K = mat.spec().bulk_modulus();
  const double lambda = K - 2.0 / 3.0 * G;
  Mat6 C = Mat6::Zero();
  C.template topLeftCorner<3, 3>().setConstant(lambda);
  for (int a = 0; a < 3; ++a) C(a, a) += 2.0 * G, C(a + 3, a + 3) = G;
  if (!failed && p.eps_p) {
    const Sym s = deviator(p.sigma[i]);
    const double s_norm = std::sqrt(ddot(s, s));
    const double Tp = p.T ? p.T[i] : 0.0, ep = p.eps_p[i];
    const double y = mat.strength().flow_stress(ep, 0.0, Tp);
    if (std::isfinite(y) && s_norm > 0 && std::sqrt(1.5) * s_norm >= (1.0 - 1e-3) * y) {
      const double de = 1e-6;
      const double H =
          std::clamp((mat.strength().flow_stress(ep + de, 0.0, Tp) - y) / de, 0.0, 1e3 * G);
      const Sym n = s / s_norm;
      C.noalias() -= 6.0 * G * G / (3.0 * G + H) * (n * n.transpose());
    }
  }
  return C;
}

/// B of a node: the strain of its unit velocities from its shape function N and gradient Gr
/// (1/m); in axisymmetry with the hoop row N / r (r: the particle's radius, m).
template <int D>
StrainMatrix<D> strain_matrix(double N, const Vec<D>& Gr, bool axisymmetric, double r) {
  StrainMatrix<D> B = StrainMatrix<D>::Zero();
  B(0, 0) = Gr[0];
  B(1, 1) = Gr[1];
  B(5, 0) = Gr[1];
  B(5, 1) = Gr[0];
  if constexpr (D == 3) {
    B(2, 2) = Gr[2];
    B(3, 1) = Gr[2];
    B(3, 2) = Gr[1];
    B(4, 0) = Gr[2];
    B(4, 2) = Gr[0];
  } else if (axisymmetric) {
    B(2, 0) = N / r;
  }
  return B;
}

}  // namespace

/// The tangent preconditioner for a step dt: the last factor while it was built for the same
/// unknowns and dt and still works (the last solve took at most 1.5 times the Krylov
/// iterations per Newton iteration of the first solve with it, plus one), else a new one.
/// The tangent changes little from step to step at small multiples, where a factor per step
/// would cost more than the Krylov iterations it saves.
template <LatticeGrid GridT>
bool ImplicitSolver<GridT>::tangent_for(double dt) {
  std::vector<std::int64_t> keys(dof_node_.size());
  for (std::size_t d = 0; d < keys.size(); ++d)
    keys[d] = global_key(dof_node_[d]) * D + dof_axis_[d];
  if (tangent_ && tangent_->valid && tangent_->dt == dt && tangent_->keys == keys &&
      tangent_->last_rate <= 1.5 * tangent_->fresh_rate + 1.0)
    return true;
  if (!factor_tangent(dt)) return false;
  TangentFactor& T = *tangent_;
  T.keys = std::move(keys);
  T.dt = dt;
  T.valid = true;
  T.fresh_rate = -1;
  return true;
}

/// The Jacobian's estimate on the unknowns, factored: A = M + theta dt^2 K_t (velocity
/// formulation; LDL^T), or I + theta dt^2 K_t W with W = M^-1 M_c M^-1 (momentum formulation,
/// whose strain comes from the remapped velocities of eq. 3.2.7: M_c = sum_p m_p N_ip N_jp the
/// consistent mass; LU). K_t is assembled from the particles
/// at the step's start, K_t = sum_p V_p B_p^T C_p B_p (in axisymmetry B has the hoop row
/// N_i / r_p), with C_p the elastic moduli, less the plastic part for a particle on its yield
/// surface: C_ep = C - 6 G^2 / (3 G + H) n n^T, n = s / |s| and H the hardening slope of its
/// flow stress (the continuum elastic-plastic tangent of J2 flow); a failed particle keeps only
/// its bulk modulus. It is the Jacobian of the internal force of a small-strain material in
/// the state at t^k: exact for a small step of a linear elastic material, an estimate for the
/// rest (the state moves during the step; geometric terms are left out). Returns false when
/// the matrix cannot be factored (the caller falls back to the diagonal).
template <LatticeGrid GridT>
bool ImplicitSolver<GridT>::factor_tangent(double dt) {
  ScopedTimer timer(timers_, timers_.id("preconditioner"));
  if (!tangent_) tangent_ = std::make_unique<TangentFactor>();
  TangentFactor& T = *tangent_;
  const std::size_t nodes = grid_.nodes(), nd = dof_node_.size();
  const bool momentum = spec_.formulation == Formulation::Momentum;
  std::vector<std::int64_t> dof_of(nodes * D, -1);  // node * D + component -> unknown
  std::vector<Eigen::Triplet<double>> entries;      // M (velocity) + theta dt^2 K_t
  std::vector<Eigen::Triplet<double>> remap;        // momentum: W = M^-1 M_c M^-1 on the unknowns
  for (std::size_t d = 0; d < nd; ++d) {
    dof_of[std::size_t(dof_node_[d]) * D + std::size_t(dof_axis_[d])] = std::int64_t(d);
    if (!momentum) entries.emplace_back(int(d), int(d), grid_.m[dof_node_[d]]);
  }
  const double c = spec_.theta * dt * dt;
  const ParticleView<D> p = view<D>(particles_);
  const bool axi = axisymmetric_;
  for_particles(
      0, std::uint32_t(binning_.bins().size()),
      [&](std::uint32_t i, const std::int64_t* nd_c, int nn, const double* N, const Vec<D>* Gr) {
        const Mat6 C = tangent_moduli(materials_[p.material[i]], p, i);
        const double V = p.m[i] / p.rho[i];
        StrainMatrix<D> B[NMAX];
        for (int a = 0; a < nn; ++a) B[a] = strain_matrix<D>(N[a], Gr[a], axi, p.x[i][0]);
        if (momentum)
          for (int a = 0; a < nn; ++a)
            for (int b = 0; b < nn; ++b)
              for (int r = 0; r < D; ++r) {
                const std::int64_t row = dof_of[std::size_t(nd_c[a]) * D + std::size_t(r)];
                const std::int64_t col = dof_of[std::size_t(nd_c[b]) * D + std::size_t(r)];
                if (row >= 0 && col >= 0 && N[a] * N[b] != 0)
                  remap.emplace_back(int(row), int(col),
                                     p.m[i] * N[a] * N[b] / (grid_.m[nd_c[a]] * grid_.m[nd_c[b]]));
              }
        for (int b = 0; b < nn; ++b) {
          const StrainMatrix<D> CB = C * B[b];
          for (int a = 0; a < nn; ++a) {
            const Mat<D> Kab = (c * V) * (B[a].transpose() * CB);
            for (int r = 0; r < D; ++r) {
              const std::int64_t row = dof_of[std::size_t(nd_c[a]) * D + std::size_t(r)];
              if (row < 0) continue;
              for (int q = 0; q < D; ++q) {
                const std::int64_t col = dof_of[std::size_t(nd_c[b]) * D + std::size_t(q)];
                if (col >= 0 && Kab(r, q) != 0) entries.emplace_back(int(row), int(col), Kab(r, q));
              }
            }
          }
        }
      });
  const auto n_unknowns = static_cast<Eigen::Index>(nd);
  Eigen::SparseMatrix<double> A(n_unknowns, n_unknowns);
  A.setFromTriplets(entries.begin(), entries.end());
  if (!momentum) return T.factor(T.ldlt, A);
  Eigen::SparseMatrix<double> W(n_unknowns, n_unknowns), I(n_unknowns, n_unknowns);
  W.setFromTriplets(remap.begin(), remap.end());
  I.setIdentity();
  Eigen::SparseMatrix<double> J = I + Eigen::SparseMatrix<double>(A * W);
  return T.factor(T.lu, J);
}

template bool ImplicitSolver<UniformGrid<2>>::tangent_for(double);
template bool ImplicitSolver<UniformGrid<3>>::tangent_for(double);
template bool ImplicitSolver<UniformGrid<2>>::factor_tangent(double);
template bool ImplicitSolver<UniformGrid<3>>::factor_tangent(double);

}  // namespace mpm
