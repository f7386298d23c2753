// Holmquist-Johnson-Cook concrete (Holmquist, Johnson & Cook 1993, the seed 004's [42];
// docs/scene.md, HJC concrete): a pressure-dependent strength softened by damage, and a
// three-region pressure with crushing, locking and an unloading path.
#include <algorithm>
#include <cmath>

#include "mpm/solver/materials/material.hpp"
#include "mpm/solver/materials/models.hpp"

namespace mpm {

namespace {

/// Malvar & Ross's (1998) dynamic increase factor of concrete's tensile strength (ACI
/// Materials Journal 95(6): the CEB-FIP form refitted to tension data), with its constants for
/// f'c worked out once: delta = 1 / (1 + 8 f'c / f'co), f'co = 10 MPa, log10 beta = 6 delta -
/// 2; at rates over the quasi-static 1e-6 /s it is (rate / 1e-6)^delta up to 1 /s and
/// beta (rate / 1e-6)^(1/3) above (the two meet at 1 /s); at most tension_dif_max; 1 for
/// tension_rate None.
struct TensionDif {
  bool on = false;
  double delta = 0, beta_cbrt = 0, cap = 1;  ///< beta_cbrt = beta / cbrt(1e-6)
  explicit TensionDif(const HjcSpec& h)
      : on(h.tension_rate != HjcSpec::TensionRate::None),
        delta(1.0 / (1.0 + 8.0 * h.fc / 10e6)),
        beta_cbrt(std::pow(10.0, 6.0 * delta - 2.0) * 100.0),
        cap(h.tension_dif_max) {}
  double operator()(double rate) const {
    constexpr double static_rate = 1e-6;
    if (!on || !(rate > static_rate)) return 1.0;
    const double dif =
        rate <= 1.0 ? std::pow(rate / static_rate, delta) : beta_cbrt * std::cbrt(rate);
    return std::min(dif, cap);
  }
  /// Particle i's factor this step, at the largest principal value of sym(L): worked out on the
  /// first call (b.tension_factor NaN) and kept; 1 without a rate-dependent tension.
  double of(const MaterialBlock& b, int i) const {
    if (!b.tension_factor) return 1.0;
    double& f = b.tension_factor[i];
    if (std::isnan(f)) f = (*this)(largest_eigenvalue(to_voigt(b.L[i])));
    return f;
  }
};

/// HJC's pressure against the volumetric strain mu = rho / rho0 - 1 (P in Pa):
///   elastic     mu <= mu_crush:               P = K_e mu, K_e = P_crush / mu_crush
///   crushing    mu_crush < mu <= mu_plock:    P linear from (mu_crush, P_crush) to
///                                              (mu_plock, P_lock)
///   fully dense mu > mu_plock:                P = K1 m + K2 m^2 + K3 m^3,
///                                              m = (mu - mu_lock) / (1 + mu_lock)
/// mu_lock is where the fully dense curve has P = 0 (the grain density's strain: 004 Table 4's
/// 0.10 is 2680 / 2440 - 1 for a grain density 2680 kg/m^3), and mu_plock where it reaches
/// P_lock, so that the loading curve is continuous (crushing up to (mu_lock, P_lock) and the
/// dense curve from zero at mu_lock would drop by P_lock there). Once crushed to mu_max, the
/// material unloads and reloads along the line from (mu_max, P(mu_max)) of modulus
/// K_u = (1 - F) K_e + F K1, F = (mu_max - mu_crush) / (mu_plock - mu_crush); past mu_plock it
/// follows the dense curve (K1 m below m = 0). HjcEos cuts tension at -T (1 - D).
struct HjcPressure {
  HjcSpec h;
  double K_e = 0;       ///< elastic bulk modulus, Pa
  double mu_plock = 0;  ///< end of crushing, on the fully dense curve at P_lock

  explicit HjcPressure(const HjcSpec& spec) : h(spec), K_e(spec.K_elastic()) {
    // The dense curve rises (the reader checks), so Newton from P_lock / K1 finds its one root.
    double m = h.P_lock / h.K1;
    for (int it = 0; it < 100; ++it) {
      const double r = dense_of(m) - h.P_lock;
      const double step = r / dense_slope_of(m);
      m -= step;
      if (std::abs(step) <= 1e-15 * std::max(m, 1e-12)) break;
    }
    mu_plock = h.mu_lock + (1.0 + h.mu_lock) * m;
  }
  double dense_of(double m) const { return m > 0 ? m * (h.K1 + m * (h.K2 + m * h.K3)) : h.K1 * m; }
  double dense_slope_of(double m) const {
    return m > 0 ? h.K1 + m * (2.0 * h.K2 + 3.0 * h.K3 * m) : h.K1;
  }
  double bar(double mu) const { return (mu - h.mu_lock) / (1.0 + h.mu_lock); }
  double crush_slope() const { return (h.P_lock - h.P_crush) / (mu_plock - h.mu_crush); }
  /// The loading (virgin) curve.
  double loading(double mu) const {
    if (mu <= h.mu_crush) return K_e * mu;
    if (mu <= mu_plock) return h.P_crush + crush_slope() * (mu - h.mu_crush);
    return dense_of(bar(mu));
  }
  /// Unloading modulus after crushing to m (mu_crush < m <= mu_plock), Pa.
  double unloading_modulus(double m) const {
    const double F = (m - h.mu_crush) / (mu_plock - h.mu_crush);
    return (1.0 - F) * K_e + F * h.K1;
  }
  /// Pressure at mu after the largest compression mu_max (Pa), before the tension cut, and
  /// dP/dmu of the stiffest path open from there (loading or unloading) in `slope`.
  double pressure(double mu, double mu_max, double& slope) const {
    const double m = std::max(mu_max, mu);
    double p;
    if (m <= h.mu_crush) {
      p = K_e * mu;
      slope = K_e;
    } else if (m <= mu_plock) {
      const double K_u = unloading_modulus(m);
      p = loading(m) - K_u * (m - mu);
      slope = std::max(K_u, crush_slope());
    } else {
      p = dense_of(bar(mu));
      slope = dense_slope_of(bar(mu)) / (1.0 + h.mu_lock);
    }
    return p;
  }
  /// Plastic volumetric strain after crushing to mu_max: where its unloading path has P = 0.
  double plastic_volumetric_strain(double mu_max) const {
    if (mu_max <= h.mu_crush) return 0.0;
    if (mu_max <= mu_plock) return mu_max - loading(mu_max) / unloading_modulus(mu_max);
    return h.mu_lock;
  }
};

/// The pressure of HJC concrete, p = A(rho, mu_max, D) with no energy term (B = 0): the curve
/// of HjcPressure cut at -T (1 - D), T at the particle's rate with a rate-dependent tension.
class HjcEos final : public Eos {
 public:
  explicit HjcEos(const MaterialSpec& m) : rho0_(m.density), curve_(m.hjc), dif_(m.hjc) {}
  /// Virgin material (no crushing, no damage) at the quasi-static rate: the loading curve.
  void coefficients(int n, const double* rho, const double* /*e*/, double* A, double* B,
                    double* K) const override {
    for (int i = 0; i < n; ++i) {
      set(i, rho[i], 0.0, A, B, K);
      A[i] = std::max(A[i], -curve_.h.T);
    }
  }
  void block_coefficients(const MaterialBlock& b, const double* /*e*/, double* A, double* B,
                          double* K) const override {
    for (int i = 0; i < b.n; ++i) {
      set(i, b.rho[i], b.mu_max ? b.mu_max[i] : 0.0, A, B, K);
      // The tension cut at -T (1 - D) times the rate factor (>= 1), which is worked out only
      // where the cut without it would hold.
      const double cut = -curve_.h.T * (1.0 - (b.damage ? b.damage[i] : 0.0));
      if (A[i] < cut) A[i] = std::max(A[i], cut * dif_.of(b, i));
    }
  }

 private:
  void set(int i, double rho, double mu_max, double* A, double* B, double* K) const {
    const double mu = rho / rho0_ - 1.0;
    double slope;
    A[i] = curve_.pressure(mu, mu_max, slope);
    B[i] = 0.0;
    K[i] = (1.0 + mu) * slope;  // rho dP/drho
  }
  double rho0_;
  HjcPressure curve_;
  TensionDif dif_;
};

/// HJC strength: sigma_y = f'c sigma*, sigma* = (A (1 - D) + B P*^N)(1 + C ln(rate*)) for
/// P* = P / f'c >= 0, at most S_max; for P* < 0 linear from A (1 - D) at P* = 0 to zero at the
/// tension cut-off P* = -T* (1 - D), T* = T / f'c. rate* = max(rate / rate0, 1) with rate the
/// equivalent deviatoric strain rate. Radial return at the flow stress of the step's start
/// (pressure at the new density, damage of t^n), then damage D += (d eps_p + d mu_p) / eps_f,
/// eps_f = max(EF_min, D1 (P* + T*)^D2), D <= 1, with mu_p the plastic volumetric strain of
/// the crushing (HjcPressure::plastic_volumetric_strain); with a damage_length the increment
/// goes to b.damage_increment, for the solver to average. With a rate-dependent tensile strength
/// T* is T hjc_tension_dif(rate_1) / f'c in the tension branch and the fracture strain, rate_1
/// the largest principal strain rate (the EOS cuts at the same T).
class HjcStrength final : public Strength {
 public:
  explicit HjcStrength(const MaterialSpec& m)
      : h_(m.hjc), rho0_(m.density), T_star_(m.hjc.T / m.hjc.fc), curve_(m.hjc), dif_(m.hjc) {}

  bool needs_plastic_strain() const override { return true; }
  bool needs_pressure() const override { return true; }
  bool rate_dependent_tension() const override { return dif_.on; }

  /// Normalised strength sigma* at P*, damage D, equivalent strain rate (1/s) and normalised
  /// tensile strength T*.
  double normalised(double P_star, double D, double rate, double T_star) const {
    const double R =
        rate > h_.reference_rate ? 1.0 + h_.C * std::log(rate / h_.reference_rate) : 1.0;
    const double s = P_star >= 0 ? h_.A * (1.0 - D) + h_.B * std::pow(P_star, h_.N)
                                 : std::max(0.0, h_.A * ((1.0 - D) + P_star / T_star));
    return std::min(s * R, h_.S_max);
  }
  /// Fracture strain at P* and T*: max(EF_min, D1 (P* + T*)^D2).
  double fracture_strain(double P_star, double T_star) const {
    return std::max(h_.EF_min, h_.D1 * std::pow(std::max(P_star + T_star, 0.0), h_.D2));
  }
  /// The intact strength at zero pressure (the implicit solver's tangent asks; HJC runs
  /// explicit only).
  double flow_stress(double, double rate, double) const override {
    return h_.fc * normalised(0.0, 0.0, rate, T_star_);
  }

  void update(MaterialBlock& b, BlockScratch& S, double G) const override {
    for (int i = 0; i < b.n; ++i) {
      const double P_star = S.p[i] / h_.fc;
      double D = b.damage ? b.damage[i] : 0.0;
      const Sym s_tr = S.s[i] + 2.0 * G * S.de[i];  // elastic predictor
      const double q_tr = std::sqrt(1.5 * ddot(s_tr, s_tr));
      const double rate = std::sqrt(2.0 / 3.0 * ddot(S.de[i], S.de[i])) / b.dt;
      // T* at the step's rate where it acts: the tension branch and the fracture strain.
      const double sy =
          h_.fc * normalised(P_star, D, rate, P_star < 0 ? T_star_ * dif_.of(b, i) : T_star_);
      double dl = 0.0;
      if (q_tr > sy) {
        dl = (q_tr - sy) / (3.0 * G);
        S.s[i] = s_tr * (sy / q_tr);  // radial return
        b.eps_p[i] += dl;
      } else {
        S.s[i] = s_tr;
      }
      S.dlambda[i] = dl;
      S.yield[i] = sy;
      // Crushing: the growth of the plastic volumetric strain as mu_max grows.
      double dmu_p = 0.0;
      if (b.mu_max) {
        const double mu = b.rho[i] / rho0_ - 1.0, m_old = b.mu_max[i];
        if (mu > m_old) {
          dmu_p = std::max(
              0.0, curve_.plastic_volumetric_strain(mu) - curve_.plastic_volumetric_strain(m_old));
          b.mu_max[i] = mu;
        }
      }
      const double dD = b.damage && dl + dmu_p > 0
                            ? (dl + dmu_p) / fracture_strain(P_star, T_star_ * dif_.of(b, i))
                            : 0.0;
      if (b.damage_increment)
        b.damage_increment[i] = dD;  // averaged over damage_length by the solver
      else if (dD > 0)
        b.damage[i] = std::min(D + dD, 1.0);
    }
  }

 private:
  HjcSpec h_;
  double rho0_, T_star_;
  HjcPressure curve_;
  TensionDif dif_;
};

}  // namespace

double hjc_tension_dif(const HjcSpec& h, double rate) {
  return TensionDif(h)(rate);
}

std::unique_ptr<Strength> make_hjc_strength(const MaterialSpec& m) {
  return std::make_unique<HjcStrength>(m);
}
std::unique_ptr<Eos> make_hjc_eos(const MaterialSpec& m) {
  return std::make_unique<HjcEos>(m);
}

}  // namespace mpm
