// Composition of a material and its constitutive update per block of particles.
#include "mpm/materials/material.hpp"

#include <cmath>
#include <stdexcept>

#include "mpm/materials/models.hpp"

namespace mpm {

std::string to_string(StrengthModel m) {
  switch (m) {
    case StrengthModel::Elastic: return "elastic";
    case StrengthModel::J2: return "j2";
    case StrengthModel::JohnsonCook: return "johnson-cook";
  }
  return "?";
}
std::string to_string(EosModel m) {
  switch (m) {
    case EosModel::Linear: return "linear";
    case EosModel::MieGruneisen: return "mie-gruneisen";
  }
  return "?";
}

const ModelRegistry& model_registry() {
  static const ModelRegistry registry = [] {
    ModelRegistry r;
    r.strength["elastic"] = make_elastic_strength;
    r.strength["j2"] = make_j2_strength;
    r.strength["johnson-cook"] = make_johnson_cook_strength;
    r.eos["linear"] = make_linear_eos;
    r.eos["mie-gruneisen"] = make_mie_gruneisen_eos;
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
}

double Material::reference_wave_speed() const {
  return std::sqrt((K_ + 4.0 / 3.0 * G_) / spec_.density);
}

void Material::update(MaterialBlock& b, BlockScratch& S) const {
  const double dt = b.dt;
  // Kinematics: strain and spin increments, Jaumann rotation, density (000, eqs. 12-15).
  for (int i = 0; i < b.n; ++i) {
    const Mat3& L = b.L[i];
    const Mat3 dE = 0.5 * dt * (L + L.transpose());  // (000, eq. 12)
    const Mat3 dW = 0.5 * dt * (L - L.transpose());  // (000, eq. 13)
    const double dvol = dE.trace();
    if (!(1.0 + dvol > 0.0)) {
      if (b.fault_index < 0) b.fault_index = i, b.fault = PointFault::VolumeInverted;
      S.dvol[i] = 0;
      S.de[i].setZero();
      S.s_old[i] = S.s[i] = deviator(b.sigma[i]);
      S.P_old[i] = -trace(b.sigma[i]) / 3.0;
      continue;
    }
    Mat3 sig = to_matrix(b.sigma[i]);
    sig += dW * sig - sig * dW;  // rotation term dr = dw.sigma - sigma.dw (000, eq. 15)
    const Sym sv = to_voigt(sig);
    S.P_old[i] = -trace(sv) / 3.0;
    S.s_old[i] = S.s[i] = deviator(sv);
    S.de[i] = deviator(to_voigt(dE));
    S.dvol[i] = dvol;
    const double rho_new = b.rho[i] / (1.0 + dvol);  // (000, eq. 14)
    b.rho[i] = rho_new;
  }

  // Deviatoric stress: elastic predictor and radial return.
  strength_->update(b, S, G_);
  // Equation of state at the new density: p = A + B e.
  eos_->coefficients(b.n, b.rho, S.A, S.B, S.K);

  const double eps_f = spec_.failure.plastic_strain;
  const double p_min = spec_.failure.pressure;
  const bool failure = spec_.failure.enabled() && b.failed;
  for (int i = 0; i < b.n; ++i) {
    const double rho = b.rho[i];
    const double dvol = S.dvol[i];
    const double trD = dvol / dt;
    const double c_bulk = std::sqrt(std::max(S.K[i], 0.0) / rho);
    // Artificial bulk viscosity in compression, linear + quadratic.
    const double q =
        trD < 0 ? rho * b.h * (bulk_quadratic_ * b.h * trD * trD - bulk_linear_ * c_bulk * trD)
                : 0.0;
    // Energy per unit mass: e_new = e + (s_old + s_new)/2 : de v_mid - (P_old + P_new)/2 dv,
    // with P = p + q, dv = dvol v_old the change of specific volume (exact: V_new = V_old
    // (1 + dvol)) and v_mid its mean. With p = A + B e_new this is solved for p at once.
    const double v_old = 1.0 / (rho * (1.0 + dvol));  // rho is already the new density
    const double k = 0.5 * dvol * v_old;
    const double v_mid = v_old * (1.0 + 0.5 * dvol);
    auto pressure = [&](const Sym& s_new, double& e_star) {
      e_star = b.e[i] + 0.5 * ddot(S.s_old[i] + s_new, S.de[i]) * v_mid - S.P_old[i] * k;
      return (S.A[i] + S.B[i] * (e_star - q * k)) / (1.0 + S.B[i] * k);
    };
    double e_star;
    double p = pressure(S.s[i], e_star);
    // Failure: no deviatoric stress, no tension (000, section 5.3).
    if (failure) {
      const bool now = b.failed[i] || (b.eps_p && b.eps_p[i] >= eps_f) || p <= p_min;
      if (now) {
        b.failed[i] = 1;
        S.s[i].setZero();
        p = pressure(S.s[i], e_star);
        if (p < 0) p = 0;
      }
    }
    b.e[i] = e_star - (p + q) * k;
    Sym sigma = S.s[i];
    sigma[0] -= p + q;
    sigma[1] -= p + q;
    sigma[2] -= p + q;
    b.sigma[i] = sigma;
    // Signal speed for the time step, widened by the viscosity as in hydrocodes:
    // dt <= h / (Q + sqrt(Q^2 + c^2)), Q = C1 c + C0 h |tr D| in compression.
    // Isentropic bulk modulus K_s = rho dp/drho at constant entropy: with p = A(rho) + B e
    // and de = p / rho^2 drho, K_s = K + B p / rho (K = rho dA/drho from the EOS). The thermal
    // term matters behind strong shocks and in hot expanded material.
    const double K_s = std::max(S.K[i], 0.0) + (p > 0 ? S.B[i] * p / rho : 0.0);
    const double c = std::sqrt((K_s + 4.0 / 3.0 * G_) / rho);
    const double Q = trD < 0 ? bulk_linear_ * c + bulk_quadratic_ * b.h * (-trD) : 0.0;
    b.c[i] = Q + std::sqrt(Q * Q + c * c);
    if (!std::isfinite(b.e[i]) || !sigma.allFinite() || !std::isfinite(rho)) {
      if (b.fault_index < 0) b.fault_index = i, b.fault = PointFault::NonFinite;
    }
  }
}

}  // namespace mpm
