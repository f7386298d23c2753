#pragma once
/// Materials are composed of an equation of state, a strength model and a failure rule, each
/// chosen by name from the scene. The solver calls Material::update once per block of
/// particles of one material (never once per particle); the strength and EOS are called once
/// per block too.
#include <algorithm>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>

#include "mpm/core/types.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm {

/// Largest number of particles in one block.
inline constexpr int kBlock = 64;

/// The stable explicit step (s) for the fastest signal `speed` (m/s) on cells of size h (m):
/// min(dt_max, cfl h / speed), dt_max when nothing moves (speed 0).
inline double stable_time_step(double dt_max, double cfl, double h, double speed) {
  return std::min(dt_max, speed > 0 ? cfl * h / speed : dt_max);
}

/// A flow stress (Pa) at or below this, in a material of shear modulus G, is round-off of a
/// zero one (the time step's test for a particle without strength).
inline double no_flow_stress(double G) {
  return 1e-9 * G;
}

/// Why a particle's update failed (instability diagnosis).
enum class PointFault : std::uint8_t { None, VolumeInverted, NonFinite };

/// The particles of one block, in and out of a constitutive update. Arrays hold `n` entries
/// and point into the particle columns (offset to the block) or into scratch.
struct MaterialBlock {
  int n = 0;
  double dt = 0;  ///< s
  double h = 0;   ///< cell size, m (length scale of the bulk viscosity)
  /// Length of the time step, m: the signal speed b.c is widened by the bulk viscosity's
  /// quadratic term with this length (step_length()), not h. On a graded grid the finest
  /// cell's, which the step is taken over, while h is the particle's own cell's. 0: h.
  double h_step = 0;
  double step_length() const { return h_step > 0 ? h_step : h; }
  const Mat3* L = nullptr;  ///< velocity gradient, 1/s; 3x3 also in 2D (zeros out of plane)
  /// Or the same one component an array (3D): L(r, c) of particle j at L_rows[3 r + c][j]; the
  /// fused update reads it in place, the others take it as L (Material::update).
  const double (*L_rows)[kBlock] = nullptr;
  const double* m = nullptr;       ///< mass, kg
  Sym* sigma = nullptr;            ///< Cauchy stress incl. bulk viscosity, Pa (in/out)
  double* rho = nullptr;           ///< density, kg/m^3 (in/out)
  double* e = nullptr;             ///< specific internal energy, J/kg (in/out)
  double* eps_p = nullptr;         ///< equivalent plastic strain (in/out; nullptr if absent)
  double* T = nullptr;             ///< temperature, K (in/out; nullptr if absent)
  std::uint8_t* failed = nullptr;  ///< failure flag (in/out; nullptr if absent)
  double* damage = nullptr;        ///< HJC damage D (in/out; nullptr if absent)
  double* mu_max = nullptr;        ///< HJC largest compression rho/rho0 - 1 (in/out; or nullptr)
  /// HJC with a damage_length: out, this step's local damage increment per particle, which the
  /// solver averages before adding it to `damage` (damage_average.hpp); damage stays that of
  /// t^n. Null: the update adds its increment to `damage` itself.
  double* damage_increment = nullptr;
  double* c = nullptr;  ///< out: signal speed for the time step, m/s
  /// The factor on a rate-dependent tensile strength this step (HJC's T), per particle: NaN
  /// until the model works it out from L, for the particles that need it (in tension, or
  /// damaging), and kept for the rest of the step. Set by the update for a strength that has
  /// one (Strength::rate_dependent_tension), else nullptr (the strength as given).
  double* tension_factor = nullptr;
  /// 2D plane stress: L(2, 2) on entry is ignored; the update finds the thickness rate that
  /// makes sigma_zz = 0 for each particle (and the density follows the thinning).
  bool plane_stress = false;
  double* thickness =
      nullptr;           ///< plane stress: thickness / initial thickness (in/out; may be null)
  int fault_index = -1;  ///< out: first particle whose update failed, -1 if none
  PointFault fault = PointFault::None;

  /// Points the state at columns from their element i0 (the optional ones null when absent).
  void set_state(Sym* sigma_, double* rho_, double* e_, double* eps_p_, double* T_,
                 std::uint8_t* failed_, double* thickness_, std::size_t i0) {
    sigma = sigma_ + i0;
    rho = rho_ + i0;
    e = e_ + i0;
    eps_p = eps_p_ ? eps_p_ + i0 : nullptr;
    T = T_ ? T_ + i0 : nullptr;
    failed = failed_ ? failed_ + i0 : nullptr;
    thickness = thickness_ ? thickness_ + i0 : nullptr;
  }
  /// Points the HJC history (damage, mu_max) at columns from element i0 (null when absent).
  void set_history(double* damage_, double* mu_max_, std::size_t i0) {
    damage = damage_ ? damage_ + i0 : nullptr;
    mu_max = mu_max_ ? mu_max_ + i0 : nullptr;
  }
};

/// Copies the state (sigma, rho, e and, where both have them, eps_p, T, failed, thickness,
/// damage and mu_max) of element i of `from` to element j of `to`: particle columns (ParticleView)
/// or a block (MaterialBlock).
template <class From, class To>
void copy_state(const From& from, std::size_t i, const To& to, std::size_t j) {
  to.sigma[j] = from.sigma[i];
  to.rho[j] = from.rho[i];
  to.e[j] = from.e[i];
  if (from.eps_p && to.eps_p) to.eps_p[j] = from.eps_p[i];
  if (from.T && to.T) to.T[j] = from.T[i];
  if (from.failed && to.failed) to.failed[j] = from.failed[i];
  if (from.thickness && to.thickness) to.thickness[j] = from.thickness[i];
  if (from.damage && to.damage) to.damage[j] = from.damage[i];
  if (from.mu_max && to.mu_max) to.mu_max[j] = from.mu_max[i];
}

/// Scratch shared by the stages of one block update (owned by the caller, one per thread).
struct BlockScratch {
  Sym de[kBlock];                          ///< deviatoric strain increment
  Sym s[kBlock];                           ///< deviatoric stress (rotated old, then new)
  Sym s_old[kBlock];                       ///< rotated old deviatoric stress
  double dvol[kBlock];                     ///< volumetric strain increment tr(D) dt
  double P_old[kBlock];                    ///< old pressure incl. viscosity, Pa
  double A[kBlock], B[kBlock], K[kBlock];  ///< EOS: p = A + B e; bulk modulus K
  double q[kBlock];                        ///< bulk viscosity, Pa
  double e_lin[kBlock];    ///< EOS nonlinear in e: the energy its tangent is taken at, J/kg
  double dlambda[kBlock];  ///< plastic strain increment of this step
  double yield[kBlock];    ///< flow stress after the step, Pa
  double p[kBlock];        ///< pressure-dependent strength: the EOS's p at the new density, Pa
  double k[kBlock];        ///< half the change of specific volume over the step, m^3/kg
  double e_star[kBlock];   ///< energy before the new pressure's work, J/kg
  double p_new[kBlock];    ///< the new pressure (without viscosity), Pa
  double tension_factor[kBlock];  ///< MaterialBlock::tension_factor
};

/// Equation of state, written as p = A(rho) + B(rho) e with e the specific internal energy,
/// so the energy equation can be solved for the new pressure without iteration. An EOS
/// nonlinear in e gives the tangent at the energy it is handed (p = A + B e exactly there,
/// B = dp/de), and the update solves the energy equation by Newton steps on it.
class Eos {
 public:
  virtual ~Eos() = default;
  /// For each particle i < n: A[i], B[i] (Pa, Pa kg/J) and the bulk modulus K[i] (Pa; rho
  /// dp/drho at constant e, or the EOS's floor under it) at density rho[i] (kg/m^3) and
  /// specific internal energy e[i] (J/kg; ignored when linear_in_energy()).
  virtual void coefficients(int n, const double* rho, const double* e, double* A, double* B,
                            double* K) const = 0;
  /// True when A, B and K do not depend on e (one solve of the energy equation is exact).
  virtual bool linear_in_energy() const { return true; }
  /// As coefficients() for the particles of a block at the energies e[i], with their history
  /// (an EOS whose pressure depends on more than rho and e, as HJC's on mu_max and damage).
  virtual void block_coefficients(const MaterialBlock& b, const double* e, double* A, double* B,
                                  double* K) const {
    coefficients(b.n, b.rho, e, A, B, K);
  }
};

/// Deviatoric strength: updates s (the rotated old deviator on entry) by the deviatoric strain
/// increment de with a radial return, and the plastic strain.
class Strength {
 public:
  virtual ~Strength() = default;
  /// Columns this model needs beyond the basic state.
  virtual bool needs_plastic_strain() const { return false; }
  virtual bool needs_temperature() const { return false; }
  /// True when the flow stress depends on the pressure: the update then hands the EOS's
  /// pressure at the new density (before the energy equation) in S.p.
  virtual bool needs_pressure() const { return false; }
  /// True when the tensile strength (of this model and its EOS) follows the strain rate:
  /// the update then hands them MaterialBlock::tension_factor.
  virtual bool rate_dependent_tension() const { return false; }
  /// Elastic-predictor / plastic-corrector for a block: in S.s (rotated s_old), S.de; out S.s,
  /// S.dlambda, S.yield, blk.eps_p, blk.T (adiabatic heating).
  virtual void update(MaterialBlock& blk, BlockScratch& S, double G) const = 0;
  /// Flow stress (Pa) at plastic strain eps_p, plastic strain rate (1/s) and temperature (K).
  virtual double flow_stress(double eps_p, double rate, double T) const = 0;
};

/// The constants of a composition that the fused update runs (fused.cpp): an elastic or
/// linear-hardening J2 strength (j2 and johnson-cook with n = 1 and neither rate nor thermal
/// term, bilinear) with a linear or Mie-Grueneisen EOS, and no failure rule. Any other
/// composition has strength None and takes the composed update.
struct FusedModel {
  enum class Strength : std::uint8_t { None, Elastic, LinearHardening };
  Strength strength = Strength::None;
  bool mie_gruneisen = false;                    ///< else the linear EOS
  double G = 0;                                  ///< shear modulus, Pa
  double A = 0, B = 0;                           ///< flow stress A + B eps_p, Pa
  double rho0 = 0;                               ///< kg/m^3
  double K = 0;                                  ///< linear EOS: bulk modulus, Pa
  double k0 = 0, s = 0, gamma0 = 0, mu_max = 0;  ///< Mie-Grueneisen: rho0 c0^2, s, gamma0, cap
  bool energy_in_expansion = true;
  double bulk_linear = 0, bulk_quadratic = 0;  ///< artificial bulk viscosity
  /// The fused composition of a material, or strength None.
  static FusedModel of(const MaterialSpec& spec, const SolverSpec& solver);
};

/// A material: reference properties plus its models.
class Material {
 public:
  Material(const MaterialSpec& spec, const SolverSpec& solver);
  const MaterialSpec& spec() const { return spec_; }
  const Strength& strength() const { return *strength_; }
  const Eos& eos() const { return *eos_; }
  double shear_modulus() const { return G_; }
  /// Constitutive update of one block (000, eqs. 12-15; Jaumann rate, radial return, EOS with
  /// internal energy, artificial bulk viscosity, failure). `S` is per-thread scratch. With
  /// `blk.plane_stress` the out-of-plane rate is solved for, per particle, by a safeguarded
  /// secant / false-position iteration on sigma_zz = 0 around the whole update (any strength,
  /// EOS and failure).
  void update(MaterialBlock& blk, BlockScratch& S) const;
  /// The update by composition: strength, EOS and failure objects stage by stage over the
  /// block (what update() runs when the composition has no fused form, or a block needs what
  /// the fused form leaves out: a failed particle, an inverted volume, plane stress).
  void update_composed(MaterialBlock& blk, BlockScratch& S) const;
  /// True when this material's composition has the fused update (FusedModel).
  bool fused() const { return fused_.strength != FusedModel::Strength::None; }
  /// Cap on the update passes of a plane-stress block (the first updates the whole block, the
  /// later ones the particles still iterating).
  static constexpr int kPlaneStressMaxPasses = 30;
  /// Signal speed (m/s) of the unstressed material: sqrt((K + 4G/3)/rho0).
  double reference_wave_speed() const;
  /// Signal speed (m/s) behind a shock of particle velocity u_p (m/s) into the material at
  /// rest, as the time step sees it: the Rankine-Hugoniot state of this
  /// EOS (rho from p(rho, u_p^2 / 2) = rho0 U_s u_p, U_s = u_p rho / (rho - rho0)), its
  /// isentropic sound speed, widened by the bulk viscosity with |tr D| = u_p / h (h cancels), plus
  /// u_p. For estimates (mpm-prep); the reference speed when u_p = 0.
  double shocked_signal_speed(double u_p) const;
  /// Density (kg/m^3) of the Rankine-Hugoniot state of a shock of particle velocity u_p > 0
  /// into the material at rest: the root of p(rho, u_p^2 / 2) = rho0 u_p^2 rho / (rho - rho0);
  /// 0 if there is none below 20 rho0.
  double hugoniot_density(double u_p) const;

 private:
  void update_once(MaterialBlock& blk, BlockScratch& S) const;
  /// The fused update of a block (fused.cpp); false, with the block untouched, when the block
  /// needs the composed one.
  bool update_fused(MaterialBlock& blk) const;
  /// One particle's energy equation over a step (material.cpp).
  struct EnergyStep {
    double q = 0;      ///< bulk viscosity, Pa
    double k = 0;      ///< half the change of specific volume, m^3/kg
    double v_mid = 0;  ///< mean specific volume over the step, m^3/kg
    /// The energy before the new pressure's work, J/kg.
    double e_star(double e, const Sym& s_old, const Sym& s_new, const Sym& de, double P_old) const {
      return e + 0.5 * ddot(s_old + s_new, de) * v_mid - P_old * k;
    }
    /// The new pressure (Pa) from p = A + B e_new, e_new = e_star - (p + q) k.
    double pressure(double A, double B, double e_star) const {
      return (A + B * (e_star - q * k)) / (1.0 + B * k);
    }
  };
  EnergyStep energy_step(const MaterialBlock& b, const BlockScratch& S, int i) const;
  void tangent_at_step_energy(const MaterialBlock& b, BlockScratch& S) const;
  void update_plane_stress(MaterialBlock& blk, BlockScratch& S) const;
  struct PlaneStressIteration;
  void update_iterating(MaterialBlock& b, PlaneStressIteration& it, const int* idx, int k,
                        BlockScratch& S) const;

  MaterialSpec spec_;
  double G_ = 0, K_ = 0;
  double K0_eos_ = 0;  ///< the EOS's bulk modulus at rho0, Pa
  double bulk_linear_ = 0, bulk_quadratic_ = 0;
  std::unique_ptr<Strength> strength_;
  std::unique_ptr<Eos> eos_;
  FusedModel fused_;
};

/// Factories by name. One explicit function registers the built-in models
/// (no static-initialiser registration: a static library would drop it).
using StrengthFactory = std::function<std::unique_ptr<Strength>(const MaterialSpec&)>;
using EosFactory = std::function<std::unique_ptr<Eos>(const MaterialSpec&)>;
struct ModelRegistry {
  std::map<std::string, StrengthFactory> strength;
  std::map<std::string, EosFactory> eos;
};
/// The registry with every built-in model: strength "elastic", "j2", "johnson-cook",
/// "bilinear", "hjc"; eos "linear", "mie-gruneisen", "tillotson", "hjc".
const ModelRegistry& model_registry();
/// Registry key of a scene enum.
std::string to_string(StrengthModel m);
std::string to_string(EosModel m);

}  // namespace mpm
