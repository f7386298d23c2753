// The Tillotson equation of state (Tillotson 1962; docs/eos-tillotson.md): compressed, cold
// expanded and hot expanded branches, blended linearly in energy between incipient and
// complete vaporisation.
#include <algorithm>
#include <cmath>

#include "mpm/solver/materials/material.hpp"
#include "mpm/solver/materials/models.hpp"

namespace mpm {

namespace {

/// A pressure and its partial derivatives: p (Pa), dp/drho at constant E (m^2/s^2) and dp/dE
/// at constant rho (kg/m^3).
struct PressureState {
  double p = 0, p_rho = 0, p_E = 0;
};

/// With eta = rho / rho0, mu = eta - 1, E the specific internal energy (J/kg) and
/// omega = 1 + E / (E0 eta^2):
///   compressed (mu >= 0), cold expanded (mu < 0, E <= E_iv):
///     p_c = (a + b / omega) rho E + A mu + B mu^2
///   hot expanded (mu < 0, E >= E_cv), z = 1 / eta - 1:
///     p_e = a rho E + (b rho E / omega + A mu exp(-beta z)) exp(-alpha z^2)
///   partial vaporisation (mu < 0, E_iv < E < E_cv):
///     p = ((E - E_iv) p_e + (E_cv - E) p_c) / (E_cv - E_iv)
/// Below zero energy (reached only through round-off: E is the integral of -p dv from the
/// reference state, which is not negative along any reversible path) the thermal terms are
/// those of E = 0, so omega stays positive however far the material expands.
class TillotsonEos final : public Eos {
 public:
  explicit TillotsonEos(const MaterialSpec& m) : rho0_(m.density), t_(m.eos.tillotson) {}

  bool linear_in_energy() const override { return false; }

  void coefficients(int n, const double* rho, const double* e, double* A, double* B,
                    double* K) const override {
    const double c2_min = t_.A / rho0_;  // the floor under dp/drho: the reference bulk speed
    for (int i = 0; i < n; ++i) {
      const PressureState s = state(rho[i], e[i]);
      B[i] = s.p_E;
      A[i] = s.p - s.p_E * e[i];  // the tangent at e[i]: p = A + B e there, to first order
      K[i] = rho[i] * std::max(s.p_rho, c2_min);
    }
  }

  /// The pressure and its derivatives at density rho (kg/m^3) and specific energy e (J/kg).
  PressureState state(double rho, double e) const {
    const double E = std::max(e, 0.0);
    const double eta = rho / rho0_, mu = eta - 1.0;
    if (mu >= 0 || E <= t_.E_iv) return compressed(rho, E, e);
    if (E >= t_.E_cv) return expanded(rho, E, e);
    // Partial vaporisation: the weights depend on E, so dp/dE gains (p_e - p_c) / (E_cv - E_iv).
    const PressureState c = compressed(rho, E, e), h = expanded(rho, E, e);
    const double dE = t_.E_cv - t_.E_iv, w = (E - t_.E_iv) / dE;
    PressureState s;
    s.p = w * h.p + (1.0 - w) * c.p;
    s.p_rho = w * h.p_rho + (1.0 - w) * c.p_rho;
    s.p_E = w * h.p_E + (1.0 - w) * c.p_E + (h.p - c.p) / dE;
    return s;
  }

 private:
  /// omega = 1 + E / (E0 eta^2) and d omega / d rho = -2 (omega - 1) / rho.
  double omega(double eta, double E) const { return 1.0 + E / (t_.E0 * eta * eta); }

  /// The compressed and cold expanded branch p_c. `e` is the energy before the floor at zero
  /// (dp/dE is zero below it).
  PressureState compressed(double rho, double E, double e) const {
    const double eta = rho / rho0_, mu = eta - 1.0, w = omega(eta, E);
    PressureState s;
    s.p = (t_.a + t_.b / w) * rho * E + t_.A * mu + t_.B * mu * mu;
    // d/drho of (b / omega) rho E = b E / omega + 2 b E (omega - 1) / omega^2.
    s.p_rho =
        E * (t_.a + t_.b / w + 2.0 * t_.b * (w - 1.0) / (w * w)) + (t_.A + 2.0 * t_.B * mu) / rho0_;
    s.p_E = e < 0 ? 0.0 : rho * (t_.a + t_.b / (w * w));  // d(E / omega)/dE = 1 / omega^2
    return s;
  }

  /// The hot expanded branch p_e (mu < 0).
  PressureState expanded(double rho, double E, double e) const {
    const double eta = rho / rho0_, mu = eta - 1.0, w = omega(eta, E);
    const double z = 1.0 / eta - 1.0, dz = -rho0_ / (rho * rho);  // dz/drho
    const double X = std::exp(-t_.beta * z), Y = std::exp(-t_.alpha * z * z);
    const double gas = t_.b * rho * E / w, cold = t_.A * mu * X;
    PressureState s;
    s.p = t_.a * rho * E + (gas + cold) * Y;
    const double d_gas = t_.b * E * (1.0 / w + 2.0 * (w - 1.0) / (w * w));
    const double d_cold = t_.A * X * (1.0 / rho0_ - t_.beta * mu * dz);
    s.p_rho = t_.a * E + (d_gas + d_cold) * Y - (gas + cold) * Y * 2.0 * t_.alpha * z * dz;
    s.p_E = e < 0 ? 0.0 : rho * (t_.a + t_.b * Y / (w * w));
    return s;
  }

  double rho0_;
  TillotsonSpec t_;
};

}  // namespace

std::unique_ptr<Eos> make_tillotson_eos(const MaterialSpec& m) {
  return std::make_unique<TillotsonEos>(m);
}

}  // namespace mpm
