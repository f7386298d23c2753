// The fused update: the common compositions (elastic or linear-hardening J2 strength with a
// linear or Mie-Grueneisen EOS, no failure) in one loop over the block, particle data as
// columns of a component each (structure of arrays), every branch a select, so that the
// compiler runs a vector of particles per iteration (8 doubles on AVX-512). The composition is
// chosen once per material (Material's constructor), not per particle; the arithmetic is that
// of the composed update (update_composed: kinematics, radial return, EOS, energy equation,
// signal speed), operation for operation, so the two agree to round-off (test_fused.cpp).
#include <algorithm>
#include <cmath>

#include "mpm/solver/materials/material.hpp"
#include "mpm/solver/materials/models.hpp"

namespace mpm {

FusedModel FusedModel::of(const MaterialSpec& spec, const SolverSpec& solver) {
  FusedModel f;
  const StrengthSpec& s = spec.strength;
  if (spec.failure.enabled()) return f;
  switch (s.model) {
    case StrengthModel::Elastic:
      f.strength = Strength::Elastic;
      break;
    case StrengthModel::J2:  // sigma_y = A + B eps_p with n = 1
      if (s.n != 1.0) return f;
      f.strength = Strength::LinearHardening, f.A = s.A, f.B = s.B;
      break;
    case StrengthModel::JohnsonCook:  // without its rate and thermal terms, J2's
      if (s.n != 1.0 || s.C != 0.0 || s.m > 0) return f;
      f.strength = Strength::LinearHardening, f.A = s.A, f.B = s.B;
      break;
    case StrengthModel::Bilinear:
      f.strength = Strength::LinearHardening, f.A = s.A, f.B = bilinear_hardening(spec);
      break;
    default:
      return f;
  }
  switch (spec.eos.model) {
    case EosModel::Linear:
      f.mie_gruneisen = false;
      break;
    case EosModel::MieGruneisen:
      f.mie_gruneisen = true;
      break;
    default:
      f.strength = Strength::None;
      return f;
  }
  f.G = spec.shear_modulus();
  f.rho0 = spec.density;
  f.K = spec.bulk_modulus();
  f.k0 = spec.density * spec.eos.c0 * spec.eos.c0;
  f.s = spec.eos.s;
  f.gamma0 = spec.eos.gamma0;
  f.mu_max = mie_gruneisen_mu_cap(spec.eos.s);
  f.energy_in_expansion = spec.eos.energy_in_expansion;
  f.bulk_linear = solver.bulk_linear;
  f.bulk_quadratic = solver.bulk_quadratic;
  return f;
}

namespace {

/// The block's velocity gradients and stresses, one array per component (the density, energy,
/// plastic strain and signal speed are columns of the block already).
struct Columns {
  alignas(64) double L[9][kBlock];  // L(r, c) in [3 r + c]
  alignas(64) double sig[6][kBlock];
};

/// The update of the block: stresses in X, the rest in the block's columns.
template <bool kPlastic, bool kMieGruneisen>
void fused_block(const FusedModel& f, MaterialBlock& b, const double (*__restrict L)[kBlock],
                 Columns& X) {
  const int n = b.n;
  const double dt = b.dt, hdt = 0.5 * dt, bh = b.h, bh_step = b.step_length();
  const double G2 = 2.0 * f.G, G3 = 3.0 * f.G, G43 = 4.0 / 3.0 * f.G;
  const double A_y = f.A, B_y = f.B, H_ret = 3.0 * f.G + f.B;
  const double rho0 = f.rho0, K_lin = f.K, k0 = f.k0, sm1 = f.s - 1.0, g0 = f.gamma0;
  const double mu_max = f.mu_max, B_mg = f.gamma0 * f.rho0;
  const double bl = f.bulk_linear, bq = f.bulk_quadratic;
  const double yield_none = no_flow_stress(f.G);
  const double B_exp = f.energy_in_expansion ? B_mg : 0.0;  // in expansion
  double* __restrict rho_p = b.rho;
  double* __restrict e_p = b.e;
  double* __restrict ep_p = kPlastic ? b.eps_p : nullptr;
  double* __restrict c_p = b.c;
#pragma omp simd
  for (int i = 0; i < n; ++i) {
    // Kinematics (material.cpp, kinematics()).
    const double dxx = dt * L[0][i], dyy = dt * L[4][i], dzz = dt * L[8][i];
    const double dyz = hdt * (L[5][i] + L[7][i]), dxz = hdt * (L[2][i] + L[6][i]),
                 dxy = hdt * (L[1][i] + L[3][i]);
    const double wxy = hdt * (L[1][i] - L[3][i]), wxz = hdt * (L[2][i] - L[6][i]),
                 wyz = hdt * (L[5][i] - L[7][i]);
    const double dvol = dxx + dyy + dzz;
    const double sxx = X.sig[0][i], syy = X.sig[1][i], szz = X.sig[2][i], syz = X.sig[3][i],
                 sxz = X.sig[4][i], sxy = X.sig[5][i];
    const double v0 = sxx + 2.0 * (wxy * sxy + wxz * sxz);
    const double v1 = syy + 2.0 * (wyz * syz - wxy * sxy);
    const double v2 = szz - 2.0 * (wxz * sxz + wyz * syz);
    const double v3 = syz + wyz * (szz - syy) - wxy * sxz - wxz * sxy;
    const double v4 = sxz + wxz * (szz - sxx) + wxy * syz - wyz * sxy;
    const double v5 = sxy + wxy * (syy - sxx) + wxz * syz + wyz * sxz;
    const double mean = (v0 + v1 + v2) / 3.0;
    const double P_old = -mean;
    const double o0 = v0 - mean, o1 = v1 - mean, o2 = v2 - mean;  // s_old: o0..o2, v3..v5
    const double dm = dvol / 3.0;
    const double e0 = dxx - dm, e1 = dyy - dm, e2 = dzz - dm;  // de: e0..e2, dyz, dxz, dxy
    const double rho = rho_p[i] / (1.0 + dvol);
    // Strength: elastic predictor and radial return (strength.cpp).
    double t0 = o0 + G2 * e0, t1 = o1 + G2 * e1, t2 = o2 + G2 * e2, t3 = v3 + G2 * dyz,
           t4 = v4 + G2 * dxz, t5 = v5 + G2 * dxy;
    double yield = 0;
    if constexpr (kPlastic) {
      const double q_tr =
          std::sqrt(1.5 * (t0 * t0 + t1 * t1 + t2 * t2 + 2.0 * (t3 * t3 + t4 * t4 + t5 * t5)));
      const double ep = ep_p[i];
      const double sy0 = A_y + B_y * ep;
      const bool plastic = q_tr > sy0;
      const double dl = plastic ? (q_tr - sy0) / H_ret : 0.0;
      const double sy = q_tr - G3 * dl;
      const double r = plastic ? sy / q_tr : 1.0;
      t0 *= r, t1 *= r, t2 *= r, t3 *= r, t4 *= r, t5 *= r;
      ep_p[i] = plastic ? ep + dl : ep;
      yield = plastic ? sy : sy0;
    }
    // Equation of state at the new density: p = A + B e, bulk modulus K (eos.cpp).
    double A, B, K;
    if constexpr (kMieGruneisen) {
      const double mu = std::min(rho / rho0 - 1.0, mu_max);
      const double den = 1.0 - sm1 * mu;
      const double pH = k0 * mu * (1.0 + mu) / (den * den);
      const double dpH =
          k0 * ((1.0 + 2.0 * mu) * den + 2.0 * sm1 * mu * (1.0 + mu)) / (den * den * den);
      const double g = 1.0 - 0.5 * g0 * mu / (1.0 + mu);
      const double dg = -0.5 * g0 / ((1.0 + mu) * (1.0 + mu));
      const bool comp = mu > 0;
      A = comp ? pH * g : k0 * mu;
      K = (1.0 + mu) * (comp ? std::max(dpH * g + pH * dg, k0) : k0);
      B = comp ? B_mg : B_exp;
    } else {
      A = K_lin * (rho / rho0 - 1.0);
      B = 0.0;
      K = K_lin * rho / rho0;
    }
    // Energy equation (material.cpp, energy_step), solved for the new pressure.
    const double trD = dvol / dt;
    const double c_bulk = bl > 0 ? std::sqrt(std::max(K, 0.0) / rho) : 0.0;
    const double q = trD < 0 ? rho * bh * (bq * bh * trD * trD - bl * c_bulk * trD) : 0.0;
    const double v_old = 1.0 / (rho * (1.0 + dvol));
    const double k = 0.5 * dvol * v_old;
    const double v_mid = v_old * (1.0 + 0.5 * dvol);
    const double work = (o0 + t0) * e0 + (o1 + t1) * e1 + (o2 + t2) * e2 +
                        2.0 * ((v3 + t3) * dyz + (v4 + t4) * dxz + (v5 + t5) * dxy);
    const double e_star = e_p[i] + 0.5 * work * v_mid - P_old * k;
    const double p = (A + B * (e_star - q * k)) / (1.0 + B * k);
    const double P = p + q;
    e_p[i] = e_star - P * k;
    X.sig[0][i] = t0 - P, X.sig[1][i] = t1 - P, X.sig[2][i] = t2 - P;
    X.sig[3][i] = t3, X.sig[4][i] = t4, X.sig[5][i] = t5;
    rho_p[i] = rho;
    // Signal speed for the time step (material.cpp, update_once).
    const double K_s = std::max(K, 0.0) + (p > 0 ? B * p / rho : 0.0);
    const bool strong = !kPlastic || yield > yield_none || rho >= rho0;
    const double c2 = strong ? (K_s + G43) / rho : K_s / rho + G43 / rho0;
    const double c = std::sqrt(c2);
    const double Q = trD < 0 ? bl * c + bq * bh_step * (-trD) : 0.0;
    c_p[i] = Q > 0 ? Q + std::sqrt(Q * Q + c * c) : c;
  }
}

}  // namespace

bool Material::update_fused(MaterialBlock& b) const {
  const int n = b.n;
  const bool plastic = fused_.strength == FusedModel::Strength::LinearHardening;
  if (plastic && !b.eps_p) return false;
  if (b.failed)  // a failed particle: the composed update, which keeps it stress-free
    for (int i = 0; i < n; ++i)
      if (b.failed[i]) return false;
  thread_local Columns X;
  const double(*L)[kBlock] = b.L_rows ? b.L_rows : X.L;  // in place, or from the matrices
  if (!b.L_rows)
    for (int i = 0; i < n; ++i) {
      const double* Li = b.L[i].data();  // column-major: L(r, c) at [r + 3 c]
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) X.L[3 * r + c][i] = Li[r + 3 * c];
    }
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < 6; ++a) X.sig[a][i] = b.sigma[i][a];
  // A volume that would invert (1 + tr(D) dt <= 0, as kinematics() has it): the composed
  // update, which reports it (a NaN gradient shows in the results instead).
  const double dt = b.dt;
  double worst = 1.0;
#pragma omp simd reduction(min : worst)
  for (int i = 0; i < n; ++i)
    worst = std::min(worst, 1.0 + (dt * L[0][i] + dt * L[4][i] + dt * L[8][i]));
  if (!(worst > 0.0)) return false;
  const FusedModel& f = fused_;
  if (plastic)
    f.mie_gruneisen ? fused_block<true, true>(f, b, L, X) : fused_block<true, false>(f, b, L, X);
  else
    f.mie_gruneisen ? fused_block<false, true>(f, b, L, X) : fused_block<false, false>(f, b, L, X);
  // Finite when every value is (or, rarely, overflowing: the scan tells). A vector of partial
  // sums: one sum in particle order would be a chain of dependent additions, 8 a particle.
  double sum = 0;
  const double* __restrict rho = b.rho;
  const double* __restrict e = b.e;
#pragma omp simd reduction(+ : sum)
  for (int i = 0; i < n; ++i)
    sum += ((X.sig[0][i] + X.sig[1][i]) + (X.sig[2][i] + X.sig[3][i])) +
           ((X.sig[4][i] + X.sig[5][i]) + (rho[i] + e[i]));
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < 6; ++a) b.sigma[i][a] = X.sig[a][i];
  if (!std::isfinite(sum) && b.fault_index < 0)
    for (int i = 0; i < n; ++i)
      if (!std::isfinite(b.e[i]) || !b.sigma[i].allFinite() || !std::isfinite(b.rho[i])) {
        b.fault_index = i, b.fault = PointFault::NonFinite;
        break;
      }
  return true;
}

}  // namespace mpm
