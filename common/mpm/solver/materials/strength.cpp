// Strength models: elastic, J2 with power-law hardening, Johnson-Cook, bilinear. Radial return.
#include <algorithm>
#include <cmath>

#include "mpm/solver/materials/material.hpp"
#include "mpm/solver/materials/models.hpp"

namespace mpm {

namespace {

class ElasticStrength final : public Strength {
 public:
  void update(MaterialBlock& b, BlockScratch& S, double G) const override {
    for (int i = 0; i < b.n; ++i) {
      if (b.failed && b.failed[i]) {
        S.s[i].setZero();
      } else {
        S.s[i] += 2.0 * G * S.de[i];
      }
      S.dlambda[i] = 0.0;
      S.yield[i] = std::numeric_limits<double>::infinity();
    }
  }
  double flow_stress(double, double, double) const override {
    return std::numeric_limits<double>::infinity();
  }
};

/// sigma_y = (A + B eps_p^n) (1 + C ln(max(rate/rate0, 1))) (1 - T*^m).
/// With C = 0 and m = 0 this is the J2 model with power-law hardening.
class PowerLawPlasticity final : public Strength {
 public:
  PowerLawPlasticity(const StrengthSpec& s, bool rate_and_thermal)
      : A_(s.A),
        B_(s.B),
        n_(s.n),
        C_(rate_and_thermal ? s.C : 0.0),
        rate0_(s.reference_rate),
        m_(rate_and_thermal ? s.m : 0.0),
        T_room_(s.room_temperature),
        T_melt_(s.melt_temperature),
        cv_(s.specific_heat),
        chi_(s.taylor_quinney) {}

  bool needs_plastic_strain() const override { return true; }
  bool needs_temperature() const override { return m_ > 0; }

  double thermal_factor(double T) const {
    if (m_ <= 0) return 1.0;
    const double Ts = std::clamp((T - T_room_) / (T_melt_ - T_room_), 0.0, 1.0);
    return 1.0 - std::pow(Ts, m_);
  }
  double hardening(double ep) const {
    return n_ == 1.0 ? A_ + B_ * ep : A_ + B_ * std::pow(std::max(ep, 0.0), n_);
  }
  double rate_factor(double rate) const {
    return (C_ > 0 && rate > rate0_) ? 1.0 + C_ * std::log(rate / rate0_) : 1.0;
  }
  double flow_stress(double ep, double rate, double T) const override {
    return hardening(ep) * rate_factor(rate) * thermal_factor(T);
  }

  void update(MaterialBlock& b, BlockScratch& S, double G) const override {
    const double dt = b.dt;
    for (int i = 0; i < b.n; ++i) {
      S.dlambda[i] = 0.0;
      if (b.failed && b.failed[i]) {
        S.s[i].setZero();
        S.yield[i] = 0.0;
        continue;
      }
      const Sym s_tr = S.s[i] + 2.0 * G * S.de[i];  // elastic predictor
      const double q_tr = std::sqrt(1.5 * ddot(s_tr, s_tr));
      const double ep = b.eps_p[i];
      const double T = b.T ? b.T[i] : T_room_;
      const double theta = thermal_factor(T);
      const double sy0 = hardening(ep) * theta;
      if (q_tr <= sy0) {
        S.s[i] = s_tr;
        S.yield[i] = sy0;
        continue;
      }
      // Plastic corrector: find dl with q_tr - 3 G dl = sigma_y(ep + dl, dl/dt, T).
      const double dl = solve_increment(q_tr, ep, theta, G, dt);
      const double sy = q_tr - 3.0 * G * dl;
      S.s[i] = s_tr * (sy / q_tr);  // radial return
      S.dlambda[i] = dl;
      S.yield[i] = sy;
      b.eps_p[i] = ep + dl;
      // Adiabatic heating, in models with thermal softening only (the others have no specific
      // heat, and their T, there when another material needs it, stays at room temperature).
      if (b.T && m_ > 0) b.T[i] += chi_ * sy * dl / (b.rho[i] * cv_);
    }
  }

 private:
  /// Safeguarded Newton on r(dl) = q_tr - 3 G dl - sigma_y(ep + dl, dl/dt) (decreasing in dl).
  double solve_increment(double q_tr, double ep, double theta, double G, double dt) const {
    if (n_ == 1.0 && C_ == 0.0)  // linear hardening: exact in one step
      return (q_tr - (A_ + B_ * ep) * theta) / (3.0 * G + B_ * theta);
    double lo = 0.0, hi = q_tr / (3.0 * G);  // r(0) > 0, r(hi) <= 0 since sigma_y >= 0
    double dl = std::min(hi, (q_tr - hardening(ep) * theta) / (3.0 * G + B_ * theta));
    for (int it = 0; it < 50; ++it) {
      const double epn = std::max(ep + dl, 1e-12);
      const double rate = dl / dt;
      const double H = hardening(epn);
      const double R = rate_factor(rate);
      const double r = q_tr - 3.0 * G * dl - H * R * theta;
      if (r > 0)
        lo = dl;
      else
        hi = dl;
      const double dH = n_ == 1.0 ? B_ : B_ * n_ * std::pow(epn, n_ - 1.0);
      const double dR = (C_ > 0 && rate > rate0_) ? C_ / std::max(dl, 1e-300) : 0.0;
      const double dr = -3.0 * G - (dH * R + H * dR) * theta;
      double next = dl - r / dr;
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);  // bisection fallback
      if (std::abs(next - dl) <= 1e-14 * std::max(1.0, dl) + 1e-300 || hi - lo < 1e-15 * hi)
        return next;
      dl = next;
    }
    return dl;
  }

  double A_, B_, n_, C_, rate0_, m_, T_room_, T_melt_, cv_, chi_;
};

}  // namespace

std::unique_ptr<Strength> make_elastic_strength(const MaterialSpec&) {
  return std::make_unique<ElasticStrength>();
}
std::unique_ptr<Strength> make_j2_strength(const MaterialSpec& m) {
  return std::make_unique<PowerLawPlasticity>(m.strength, false);
}
std::unique_ptr<Strength> make_johnson_cook_strength(const MaterialSpec& m) {
  return std::make_unique<PowerLawPlasticity>(m.strength, true);
}
double bilinear_hardening(const MaterialSpec& m) {
  const double E = m.youngs_modulus, E_T = m.strength.tangent_modulus;
  return E * E_T / (E - E_T);
}
std::unique_ptr<Strength> make_bilinear_strength(const MaterialSpec& m) {
  StrengthSpec s = m.strength;
  s.B = bilinear_hardening(m);
  s.n = 1.0;
  return std::make_unique<PowerLawPlasticity>(s, false);
}

}  // namespace mpm
