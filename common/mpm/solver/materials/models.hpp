#pragma once
/// Constructors of the built-in models, used by the registry in material.cpp.
#include <memory>

#include "mpm/solver/materials/material.hpp"

namespace mpm {
std::unique_ptr<Eos> make_linear_eos(const MaterialSpec& m);
std::unique_ptr<Eos> make_mie_gruneisen_eos(const MaterialSpec& m);
/// Tillotson (docs/eos-tillotson.md): compressed, cold and hot expanded branches.
std::unique_ptr<Eos> make_tillotson_eos(const MaterialSpec& m);
std::unique_ptr<Strength> make_elastic_strength(const MaterialSpec& m);
/// Isotropic hardening sigma_y = A + B eps_p^n (no rate or thermal term).
std::unique_ptr<Strength> make_j2_strength(const MaterialSpec& m);
/// Johnson-Cook: (A + B eps_p^n)(1 + C ln(rate/rate0))(1 - T*^m), adiabatic heating.
std::unique_ptr<Strength> make_johnson_cook_strength(const MaterialSpec& m);
/// Bilinear elastic-plastic: J2 with sigma_y = A + H eps_p, H = E E_T / (E - E_T).
std::unique_ptr<Strength> make_bilinear_strength(const MaterialSpec& m);
/// The bilinear model's hardening modulus H = E E_T / (E - E_T): uniaxial stress, d sigma =
/// E (d eps - d eps_p) and d sigma = H d eps_p, gives the slope E H / (E + H) = E_T after yield.
double bilinear_hardening(const MaterialSpec& m);
/// Mie-Grueneisen's cap on the compression mu: its Hugoniot is singular at mu = 1/(s - 1), and
/// the EOS stops 5% short of it (compression ratios beyond are outside the fitted shock data).
inline double mie_gruneisen_mu_cap(double s) {
  return s > 1.0 ? 0.95 / (s - 1.0) : 1e9;
}
/// Holmquist-Johnson-Cook concrete (hjc.cpp): the strength with its damage, and the
/// three-region pressure with its unloading path and the damaged tension cut-off.
std::unique_ptr<Strength> make_hjc_strength(const MaterialSpec& m);
std::unique_ptr<Eos> make_hjc_eos(const MaterialSpec& m);
/// The factor on HJC's tensile strength T at a largest principal strain rate (1/s): 1 for
/// tension_rate None, else Malvar and Ross's (1998) dynamic increase factor for f'c, at most
/// tension_dif_max.
double hjc_tension_dif(const HjcSpec& h, double rate);
}  // namespace mpm
