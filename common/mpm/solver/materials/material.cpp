// Composition of a material and its constitutive update per block of particles.
#include "mpm/solver/materials/material.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "mpm/solver/materials/models.hpp"

namespace mpm {

namespace {
/// Isentropic bulk modulus of p = A(rho) + B e: K_s = rho dp/drho at constant entropy
/// = K + B p / rho (K = rho dA/drho from the EOS; de = p / rho^2 drho). The thermal term
/// matters behind strong shocks and in hot expanded material.
double isentropic_bulk(double K, double B, double p, double rho) {
  return std::max(K, 0.0) + (p > 0 ? B * p / rho : 0.0);
}
/// The signal speed the time step uses: sound speed c widened by the bulk viscosity, as in
/// hydrocodes: dt <= h / (Q + sqrt(Q^2 + c^2)), Q = C1 c + C0 h |tr D| in compression.
double widened(double c, double Q) {
  return Q > 0 ? Q + std::sqrt(Q * Q + c * c) : c;  // sqrt(c^2) is c in binary floating point
}
}  // namespace

// The energy equation of one particle over a step: e_new = e + (s_old + s_new)/2 : de v_mid -
// (P_old + P_new)/2 dv, with P = p + q, dv = dvol v_old the change of specific volume (exact:
// V_new = V_old (1 + dvol)) and v_mid its mean. With p = A + B e_new it is solved for p at once.
Material::EnergyStep Material::energy_step(const MaterialBlock& b, const BlockScratch& S,
                                           int i) const {
  const double rho = b.rho[i];
  const double dvol = S.dvol[i];
  const double trD = dvol / b.dt;
  EnergyStep es;
  // Artificial bulk viscosity in compression, linear + quadratic (the bulk sound speed only
  // there: a square root is the dearest thing in this loop).
  if (trD < 0) {
    const double c_bulk = bulk_linear_ > 0 ? std::sqrt(std::max(S.K[i], 0.0) / rho) : 0.0;
    es.q = rho * b.h * (bulk_quadratic_ * b.h * trD * trD - bulk_linear_ * c_bulk * trD);
  }
  const double v_old = 1.0 / (rho * (1.0 + dvol));  // rho is already the new density
  es.k = 0.5 * dvol * v_old;
  es.v_mid = v_old * (1.0 + 0.5 * dvol);
  return es;
}

// An EOS nonlinear in e: its tangent at the energy of t^n gives the first Newton iterate of
// the energy equation, e_1 = e* - (p_1 + q) k (no failure yet: an estimate); the update then
// solves it on the tangent at e_1, the second Newton iterate (its error is (dp/de)' (e_2 -
// e_1)^2 k / 2, second order in the step's energy change).
void Material::tangent_at_step_energy(const MaterialBlock& b, BlockScratch& S) const {
  eos_->block_coefficients(b, b.e, S.A, S.B, S.K);
  for (int i = 0; i < b.n; ++i) {
    const EnergyStep es = energy_step(b, S, i);
    const double e_star = es.e_star(b.e[i], S.s_old[i], S.s[i], S.de[i], S.P_old[i]);
    const double p = es.pressure(S.A[i], S.B[i], e_star);
    S.e_lin[i] = e_star - (p + es.q) * es.k;
  }
  eos_->block_coefficients(b, S.e_lin, S.A, S.B, S.K);
}

std::string to_string(StrengthModel m) {
  switch (m) {
    case StrengthModel::Elastic:
      return "elastic";
    case StrengthModel::J2:
      return "j2";
    case StrengthModel::JohnsonCook:
      return "johnson-cook";
    case StrengthModel::Bilinear:
      return "bilinear";
    case StrengthModel::Hjc:
      return "hjc";
  }
  return "?";
}
std::string to_string(EosModel m) {
  switch (m) {
    case EosModel::Linear:
      return "linear";
    case EosModel::MieGruneisen:
      return "mie-gruneisen";
    case EosModel::Tillotson:
      return "tillotson";
    case EosModel::Hjc:
      return "hjc";
  }
  return "?";
}

const ModelRegistry& model_registry() {
  static const ModelRegistry registry = [] {
    ModelRegistry r;
    r.strength["elastic"] = make_elastic_strength;
    r.strength["j2"] = make_j2_strength;
    r.strength["johnson-cook"] = make_johnson_cook_strength;
    r.strength["bilinear"] = make_bilinear_strength;
    r.strength["hjc"] = make_hjc_strength;
    r.eos["linear"] = make_linear_eos;
    r.eos["mie-gruneisen"] = make_mie_gruneisen_eos;
    r.eos["tillotson"] = make_tillotson_eos;
    r.eos["hjc"] = make_hjc_eos;
    return r;
  }();
  return registry;
}

Material::Material(const MaterialSpec& spec, const SolverSpec& solver)
    : spec_(spec),
      G_(spec.shear_modulus()),
      K_(spec.bulk_modulus()),
      bulk_linear_(solver.bulk_linear),
      bulk_quadratic_(solver.bulk_quadratic) {
  const auto& reg = model_registry();
  const auto s = reg.strength.find(to_string(spec.strength.model));
  const auto e = reg.eos.find(to_string(spec.eos.model));
  if (s == reg.strength.end() || e == reg.eos.end())
    throw std::logic_error("material '" + spec.name + "': model not registered");
  strength_ = s->second(spec);
  eos_ = e->second(spec);
  double rho0 = spec.density, e0 = 0, A, B;
  eos_->coefficients(1, &rho0, &e0, &A, &B, &K0_eos_);
  fused_ = FusedModel::of(spec, solver);
}

double Material::reference_wave_speed() const {
  return std::sqrt((K_ + 4.0 / 3.0 * G_) / spec_.density);
}

double Material::hugoniot_density(double u_p) const {
  const double rho0 = spec_.density;
  const double e = 0.5 * u_p * u_p;  // energy jump of a shock from rest
  // f(rho) = p(rho, e) - rho0 U_s u_p rises from -inf at rho0+ (U_s -> inf); bisect for its
  // root on (rho0, 20 rho0] (the EOS caps compression; a root beyond is no estimate anyway).
  auto f = [&](double rho) {
    double A, B, K;
    eos_->coefficients(1, &rho, &e, &A, &B, &K);
    return A + B * e - rho0 * u_p * u_p * rho / (rho - rho0);
  };
  double lo = rho0 * (1 + 1e-12), hi = 20 * rho0;
  if (!(u_p > 0) || f(hi) < 0) return 0.0;
  for (int it = 0; it < 200 && hi - lo > 1e-13 * rho0; ++it) {
    const double mid = 0.5 * (lo + hi);
    (f(mid) < 0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double Material::shocked_signal_speed(double u_p) const {
  if (!(u_p > 0)) return reference_wave_speed();
  const double rho = hugoniot_density(u_p);
  if (!(rho > 0)) return reference_wave_speed() + u_p;
  const double e = 0.5 * u_p * u_p;
  double A, B, K;
  eos_->coefficients(1, &rho, &e, &A, &B, &K);
  const double c = std::sqrt((isentropic_bulk(K, B, A + B * e, rho) + 4.0 / 3.0 * G_) / rho);
  return widened(c, bulk_linear_ * c + bulk_quadratic_ * u_p) + u_p;
}

void Material::update(MaterialBlock& b, BlockScratch& S) const {
  if (fused() && !b.plane_stress && update_fused(b)) return;
  if (!b.L) {  // the gradients one component an array: as matrices for the composed update
    thread_local Mat3 L[kBlock];
    for (int j = 0; j < b.n; ++j)
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) L[j](r, c) = b.L_rows[3 * r + c][j];
    b.L = L;
  }
  update_composed(b, S);
}

void Material::update_composed(MaterialBlock& b, BlockScratch& S) const {
  if (b.plane_stress)
    update_plane_stress(b, S);
  else
    update_once(b, S);
}

// Plane stress: the thickness rate d = L_zz is the one that leaves sigma_zz = 0 after the
// step. sigma_zz(d) rises with d (by (K + 4G/3) dt elastically, less when plastic), so each
// particle's root is found from the elastic estimate by Newton steps with the elastic slope,
// then secant steps, until the root is bracketed, and inside the bracket by the Illinois
// variant of false position (superlinear also where sigma_zz(d) has kinks: yield, the bulk
// viscosity switching on in compression, failure). Every evaluation runs the whole update from
// the saved state of t^n, so the strength model, the EOS, the bulk viscosity and failure need
// no plane-stress variant of their own.

namespace {
/// One particle's search for the root of sigma_zz(d) = 0.
struct ThicknessRoot {
  double d = 0, d_prev = 0, r_prev = 0;  ///< rate d = L_zz (1/s); the last one, its sigma_zz
  double lo = -std::numeric_limits<double>::infinity(), r_lo = 0;  ///< bracket: r_lo < 0 < r_hi
  double hi = std::numeric_limits<double>::infinity(), r_hi = 0;
  int side = 0;  ///< which end the last evaluation replaced: -1 lo, +1 hi, 0 none yet
  bool done = false;

  /// The next rate from sigma_zz = r at d after update pass `pass` (>= 1): false when the
  /// particle has converged (then done), L being its velocity gradient, M = K + 4G/3 and
  /// k0 = M dt the elastic slope; `s` its stress.
  bool advance(const Sym& s, const Mat3& L, double M, double k0, double dt, int pass) {
    constexpr double inf = std::numeric_limits<double>::infinity();
    const double r = s[2];
    const double rate_scale =
        std::abs(L(0, 0)) + std::abs(L(1, 1)) + std::abs(L(0, 1)) + std::abs(d);
    // Converged: sigma_zz below 1e-12 of the stress, or within a few units of round-off of
    // a stress from the density (M x 1e-16: a particle at rest under noise-level stresses has
    // nothing finer to converge to), or not finite (the update reports that).
    const double scale =
        std::max({std::abs(s[0]), std::abs(s[1]), std::abs(s[5])}) + k0 * rate_scale;
    if (!(std::abs(r) > 1e-12 * scale + 1e-15 * M) || !std::isfinite(r)) {
      done = true;
      return false;
    }
    if (r > 0) {
      if (side == 1) r_lo *= 0.5;  // Illinois: the other end was kept twice
      hi = d, r_hi = r, side = 1;
    } else {
      if (side == -1) r_hi *= 0.5;
      lo = d, r_lo = r, side = -1;
    }
    double next;
    if (lo > -inf && hi < inf) {
      next = (lo * r_hi - hi * r_lo) / (r_hi - r_lo);
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      // No root left to find: a jump of sigma_zz(d) (the EOS's thermal term switching off
      // at rho0), or a bracket narrower than a representable change of the density.
      if (hi - lo <= 1e-9 * rate_scale || (hi - lo) * dt <= 1e-15) done = true;
    } else {
      next = d - r / k0;
      if (pass > 1 && r != r_prev && d != d_prev) {
        const double slope = (r - r_prev) / (d - d_prev);
        if (slope > 0) next = d - r / slope;
      }
    }
    d_prev = d;
    r_prev = r;
    if (std::abs(next - d) <= 1e-13 * rate_scale || std::abs(next - d) * dt <= 1e-16)
      done = true;  // a step at round-off
    if (done) return false;
    d = next;
    return true;
  }
};
}  // namespace

/// A block's plane-stress iteration: the state of t^n, the velocity gradients and each
/// particle's root search and fault.
struct Material::PlaneStressIteration {
  Sym sigma0[kBlock];
  double rho0[kBlock], e0[kBlock], ep0[kBlock], T0[kBlock], D0[kBlock], mm0[kBlock];
  std::uint8_t f0[kBlock];
  MaterialBlock start;  ///< the state of t^n: those columns (the ones the block has)
  Mat3 L[kBlock];
  ThicknessRoot root[kBlock];
  PointFault fault_of[kBlock];
};

void Material::update_plane_stress(MaterialBlock& b, BlockScratch& S) const {
  const int n = b.n;
  PlaneStressIteration it;
  const double lambda = K_ - 2.0 * G_ / 3.0, M = K_ + 4.0 / 3.0 * G_;
  const double k0 = M * b.dt;  // elastic d sigma_zz / d L_zz
  it.start.set_state(it.sigma0, it.rho0, it.e0, b.eps_p ? it.ep0 : nullptr, b.T ? it.T0 : nullptr,
                     b.failed ? it.f0 : nullptr, nullptr, 0);
  it.start.set_history(b.damage ? it.D0 : nullptr, b.mu_max ? it.mm0 : nullptr, 0);
  for (int i = 0; i < n; ++i) {
    copy_state(b, i, it.start, i);
    it.L[i] = b.L[i];
    // Elastic estimate from the old sigma_zz and the in-plane rate.
    it.root[i].d = -(lambda * (it.L[i](0, 0) + it.L[i](1, 1)) + it.sigma0[i][2] / b.dt) / M;
    it.L[i](2, 2) = it.root[i].d;
  }
  // Pass 0 updates the whole block in place; later passes only the particles not yet
  // converged, gathered into a sub-block (a kink or a jump of sigma_zz(d) in one particle, where
  // the root needs many passes, must not make the other 63 repeat their update).
  const Mat3* L_in = b.L;
  b.L = it.L;
  update_once(b, S);
  for (int i = 0; i < n; ++i) it.fault_of[i] = PointFault::None;
  if (b.fault_index >= 0) it.fault_of[b.fault_index] = b.fault;
  for (int pass = 1; pass < kPlaneStressMaxPasses; ++pass) {
    int idx[kBlock], k = 0;
    for (int i = 0; i < n; ++i)
      if (!it.root[i].done && it.root[i].advance(b.sigma[i], it.L[i], M, k0, b.dt, pass))
        idx[k++] = i;
    if (k == 0) break;
    update_iterating(b, it, idx, k, S);
  }
  b.fault_index = -1;
  b.fault = PointFault::None;
  for (int i = 0; i < n && b.fault_index < 0; ++i)
    if (it.fault_of[i] != PointFault::None) b.fault_index = i, b.fault = it.fault_of[i];
  b.L = L_in;
  if (b.thickness)  // as the density: V_new = V_old (1 + tr(D) dt), of which (1 + d dt) across
    for (int i = 0; i < n; ++i) b.thickness[i] *= 1.0 + it.L[i](2, 2) * b.dt;
}

// Updates the sub-block of the particles idx[0, k) still iterating from their state of t^n,
// at their next rates, into the block b.
void Material::update_iterating(MaterialBlock& b, PlaneStressIteration& it, const int* idx, int k,
                                BlockScratch& S) const {
  Sym g_sigma[kBlock];
  double g_rho[kBlock], g_e[kBlock], g_ep[kBlock], g_T[kBlock], g_m[kBlock], g_c[kBlock];
  double g_D[kBlock], g_mm[kBlock], g_dD[kBlock];
  std::uint8_t g_f[kBlock];
  Mat3 g_L[kBlock];
  MaterialBlock g = b;
  g.n = k;
  g.L = g_L;
  g.m = g_m;
  g.set_state(g_sigma, g_rho, g_e, b.eps_p ? g_ep : nullptr, b.T ? g_T : nullptr,
              b.failed ? g_f : nullptr, nullptr, 0);
  g.set_history(b.damage ? g_D : nullptr, b.mu_max ? g_mm : nullptr, 0);
  g.damage_increment = b.damage_increment ? g_dD : nullptr;
  g.c = g_c;
  g.fault_index = -1;
  g.fault = PointFault::None;
  for (int j = 0; j < k; ++j) {
    const int i = idx[j];
    it.L[i](2, 2) = it.root[i].d;
    g_L[j] = it.L[i];
    g_m[j] = b.m[i];
    copy_state(it.start, i, g, j);
    it.fault_of[i] = PointFault::None;
  }
  update_once(g, S);
  if (g.fault_index >= 0) it.fault_of[idx[g.fault_index]] = g.fault;
  for (int j = 0; j < k; ++j) {
    const int i = idx[j];
    copy_state(g, j, b, i);
    b.c[i] = g_c[j];
    if (b.damage_increment) b.damage_increment[i] = g_dD[j];
  }
}

namespace {
/// Kinematics: strain and spin increments, Jaumann rotation, density (000, eqs. 12-15),
/// component by component in Voigt order (xx, yy, zz, yz, xz, xy): the rotation term
/// dW.sigma - sigma.dW of a symmetric sigma and a skew dW is symmetric, 24 products where the
/// 3x3 matrix products took 54, and nothing goes through memory but the block's columns.
/// Out: S.dvol, S.de, S.s_old = S.s (rotated deviator), S.P_old; b.rho at the new volume.
void kinematics(MaterialBlock& b, BlockScratch& S) {
  const double dt = b.dt;
  for (int i = 0; i < b.n; ++i) {
    const Mat3& L = b.L[i];
    const double h = 0.5 * dt;
    const double dxx = dt * L(0, 0), dyy = dt * L(1, 1), dzz = dt * L(2, 2);  // (000, eq. 12)
    const double dyz = h * (L(1, 2) + L(2, 1)), dxz = h * (L(0, 2) + L(2, 0)),
                 dxy = h * (L(0, 1) + L(1, 0));
    const double wxy = h * (L(0, 1) - L(1, 0)), wxz = h * (L(0, 2) - L(2, 0)),
                 wyz = h * (L(1, 2) - L(2, 1));  // dW above the diagonal (000, eq. 13)
    const double dvol = dxx + dyy + dzz;
    const Sym& s0 = b.sigma[i];
    if (!(1.0 + dvol > 0.0)) [[unlikely]] {
      if (b.fault_index < 0) b.fault_index = i, b.fault = PointFault::VolumeInverted;
      S.dvol[i] = 0;
      S.de[i].setZero();
      S.s_old[i] = S.s[i] = deviator(s0);
      S.P_old[i] = -trace(s0) / 3.0;
      continue;
    }
    const double sxx = s0[0], syy = s0[1], szz = s0[2], syz = s0[3], sxz = s0[4], sxy = s0[5];
    // sigma + dW.sigma - sigma.dW (000, eq. 15).
    Sym sv;
    sv[0] = sxx + 2.0 * (wxy * sxy + wxz * sxz);
    sv[1] = syy + 2.0 * (wyz * syz - wxy * sxy);
    sv[2] = szz - 2.0 * (wxz * sxz + wyz * syz);
    sv[3] = syz + wyz * (szz - syy) - wxy * sxz - wxz * sxy;
    sv[4] = sxz + wxz * (szz - sxx) + wxy * syz - wyz * sxy;
    sv[5] = sxy + wxy * (syy - sxx) + wxz * syz + wyz * sxz;
    const double m = (sv[0] + sv[1] + sv[2]) / 3.0;
    S.P_old[i] = -m;
    Sym sd = sv;
    sd[0] -= m, sd[1] -= m, sd[2] -= m;
    S.s_old[i] = sd;
    S.s[i] = sd;
    const double dm = dvol / 3.0;
    Sym de;
    de << dxx - dm, dyy - dm, dzz - dm, dyz, dxz, dxy;
    S.de[i] = de;
    S.dvol[i] = dvol;
    b.rho[i] = b.rho[i] / (1.0 + dvol);  // (000, eq. 14)
  }
}
}  // namespace

void Material::update_once(MaterialBlock& b, BlockScratch& S) const {
  const double dt = b.dt;
  kinematics(b, S);
  if (strength_->rate_dependent_tension()) {
    std::fill_n(S.tension_factor, b.n, std::numeric_limits<double>::quiet_NaN());
    b.tension_factor = S.tension_factor;
  } else {
    b.tension_factor = nullptr;
  }

  // A pressure-dependent strength (HJC) takes the EOS's pressure at the new density and the
  // energy of t^n (exact for an EOS without energy; the energy equation follows below).
  if (strength_->needs_pressure()) {
    eos_->block_coefficients(b, b.e, S.A, S.B, S.K);
    for (int i = 0; i < b.n; ++i) S.p[i] = S.A[i] + S.B[i] * b.e[i];
  }
  // Deviatoric stress: elastic predictor and radial return.
  strength_->update(b, S, G_);
  // Equation of state at the new density: p = A + B e.
  if (eos_->linear_in_energy())
    eos_->block_coefficients(b, b.e, S.A, S.B, S.K);
  else
    tangent_at_step_energy(b, S);

  // The energy equation and the new stress, in short passes over the block (a loop whose
  // body is a few dozen instructions without calls keeps several particles in flight, or is
  // vectorised; one long body with the failure branch in it ran one particle at a time).
  const int n = b.n;
  double* q = S.q;
  double* k = S.k;
  double* e_star = S.e_star;
  double* p = S.p_new;
  for (int i = 0; i < n; ++i) {
    const EnergyStep es = energy_step(b, S, i);
    q[i] = es.q, k[i] = es.k;
    e_star[i] = es.e_star(b.e[i], S.s_old[i], S.s[i], S.de[i], S.P_old[i]);
    p[i] = es.pressure(S.A[i], S.B[i], e_star[i]);
  }
  // Failure: no deviatoric stress, no tension (000, section 5.3).
  const double eps_f = spec_.failure.plastic_strain;
  const double p_min = spec_.failure.pressure;
  const bool failure = spec_.failure.enabled() && b.failed;
  if (failure)
    for (int i = 0; i < n; ++i) {
      if (!(b.failed[i] || (b.eps_p && b.eps_p[i] >= eps_f) || p[i] <= p_min)) continue;
      b.failed[i] = 1;
      S.s[i].setZero();
      const EnergyStep es = energy_step(b, S, i);
      e_star[i] = es.e_star(b.e[i], S.s_old[i], S.s[i], S.de[i], S.P_old[i]);
      p[i] = std::max(es.pressure(S.A[i], S.B[i], e_star[i]), 0.0);
    }
  const double G43 = 4.0 / 3.0 * G_, c2_rest = K0_eos_ / spec_.density;
  const double yield_none = no_flow_stress(G_);
  const double h_step = b.step_length();
  for (int i = 0; i < n; ++i) {
    const double rho = b.rho[i], P = p[i] + q[i];
    b.e[i] = e_star[i] - P * k[i];
    Sym sigma = S.s[i];
    sigma[0] -= P;
    sigma[1] -= P;
    sigma[2] -= P;
    b.sigma[i] = sigma;
    // Signal speed for the time step: the isentropic sound speed, widened by the viscosity.
    const double K_s = isentropic_bulk(S.K[i], S.B[i], p[i], rho);
    // A failed particle has no shear stiffness (s = 0), and with its pressure clamped at zero
    // in expansion none at all: it moves ballistically until it is compressed back towards
    // rho0, where waves start at the EOS's bulk speed there. Without this its G / rho and the
    // EOS's floor under K made the expanding debris of V4 (rho ~ rho0 / 300) set the step
    // with 21 km/s where no wave can run.
    // A particle whose flow stress is zero after the step (HJC concrete fully damaged at zero
    // pressure or in tension) carries no shear stress now, but gains strength as soon as it is
    // compressed again: its shear term is kept (the step stays as short as the intact
    // material's, for debris that is recompressed), at the density it would regain it at,
    // rho0, not its own. With its own, such debris of V5 flung off the slab's rear face at
    // rho0 / 3000 set a step of 22 ns (sqrt(4G / 3 rho) = 130 km/s).
    const bool failed_now = failure && b.failed[i];
    double c2 = failed_now                                        ? K_s / rho
                : S.yield[i] > yield_none || rho >= spec_.density ? (K_s + G43) / rho
                                                                  : K_s / rho + G43 / spec_.density;
    if (failed_now && p[i] <= 0 && q[i] <= 0) c2 = std::min(c2, c2_rest);
    const double c = std::sqrt(c2);
    const double trD = S.dvol[i] / dt;
    const double Q = trD < 0 ? bulk_linear_ * c + bulk_quadratic_ * h_step * (-trD) : 0.0;
    b.c[i] = widened(c, Q);
  }
  if (b.fault_index < 0)
    for (int i = 0; i < n; ++i)
      if (!std::isfinite(b.e[i]) || !b.sigma[i].allFinite() || !std::isfinite(b.rho[i])) {
        b.fault_index = i, b.fault = PointFault::NonFinite;
        break;
      }
}

}  // namespace mpm
