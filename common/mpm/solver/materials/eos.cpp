// Equations of state: linear (p = K mu) and Mie-Grueneisen (000, eq. 18).
#include <algorithm>
#include <cmath>

#include "mpm/solver/materials/material.hpp"
#include "mpm/solver/materials/models.hpp"

namespace mpm {

namespace {

/// p = K mu, mu = rho/rho0 - 1; no dependence on internal energy. The bulk modulus it reports
/// is rho dp/drho = K rho / rho0, so c^2 = K / rho0 at any density (as for the
/// Mie-Grueneisen's expansion branch); K alone gave c^2 = K / rho, c too low in compression.
class LinearEos final : public Eos {
 public:
  explicit LinearEos(const MaterialSpec& m) : rho0_(m.density), K_(m.bulk_modulus()) {}
  void coefficients(int n, const double* rho, const double* /*e*/, double* A, double* B,
                    double* K) const override {
    for (int i = 0; i < n; ++i) {
      A[i] = K_ * (rho[i] / rho0_ - 1.0);
      B[i] = 0.0;
      K[i] = K_ * rho[i] / rho0_;
    }
  }

 private:
  double rho0_, K_;
};

/// Mie-Grueneisen with a linear shock-particle velocity Hugoniot, as in (000, eq. 18):
///   mu > 0: p = rho0 c0^2 mu (1 + mu) / [1 - (s - 1) mu]^2 (1 - gamma mu / 2) + gamma0 E
///   mu < 0: p = rho0 c0^2 mu + gamma0 E
/// with gamma = gamma0 rho0 / rho and E = rho0 e the internal energy per initial volume.
class MieGruneisenEos final : public Eos {
 public:
  explicit MieGruneisenEos(const MaterialSpec& m)
      : rho0_(m.density),
        c0_(m.eos.c0),
        s_(m.eos.s),
        gamma0_(m.eos.gamma0),
        mu_max_(mie_gruneisen_mu_cap(m.eos.s)),
        energy_in_expansion_(m.eos.energy_in_expansion) {}
  void coefficients(int n, const double* rho, const double* /*e*/, double* A, double* B,
                    double* K) const override {
    const double k0 = rho0_ * c0_ * c0_;
    for (int i = 0; i < n; ++i) {
      const double mu = std::min(rho[i] / rho0_ - 1.0, mu_max_);
      B[i] = gamma0_ * rho0_;
      if (mu > 0) {
        const double den = 1.0 - (s_ - 1.0) * mu;
        const double pH = k0 * mu * (1.0 + mu) / (den * den);
        const double dpH =
            k0 * ((1.0 + 2.0 * mu) * den + 2.0 * (s_ - 1.0) * mu * (1.0 + mu)) / (den * den * den);
        const double g = 1.0 - 0.5 * gamma0_ * mu / (1.0 + mu);
        const double dg = -0.5 * gamma0_ / ((1.0 + mu) * (1.0 + mu));
        A[i] = pH * g;
        K[i] = (1.0 + mu) * std::max(dpH * g + pH * dg, k0);
      } else {
        A[i] = k0 * mu;
        // rho dA/drho = k0 rho / rho0: c = c0 at any expansion. (A floor under it, as there
        // was, makes c grow like rho^-1/2 in debris expanded thousands of times, 20-40 km/s in
        // V4's cloud at rho0 / 5000, and that set the time step whenever such debris was
        // recompressed.)
        K[i] = k0 * (1.0 + mu);
        if (!energy_in_expansion_) B[i] = 0.0;  // p = rho0 c0^2 mu only
      }
    }
  }

 private:
  double rho0_, c0_, s_, gamma0_, mu_max_;
  bool energy_in_expansion_;
};

}  // namespace

std::unique_ptr<Eos> make_linear_eos(const MaterialSpec& m) {
  return std::make_unique<LinearEos>(m);
}
std::unique_ptr<Eos> make_mie_gruneisen_eos(const MaterialSpec& m) {
  return std::make_unique<MieGruneisenEos>(m);
}

}  // namespace mpm
