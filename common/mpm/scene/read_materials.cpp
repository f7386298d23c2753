// The scene parser's [materials.<name>] tables: elasticity, strength, equation of state, failure.
#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "mpm/core/error.hpp"
#include "mpm/scene/read_sections.hpp"

namespace mpm::scene_toml {

namespace {

const std::initializer_list<std::string_view> kHjcStrengthKeys = {"N",
                                                                  "fc",
                                                                  "T",
                                                                  "S_max",
                                                                  "D1",
                                                                  "D2",
                                                                  "EF_min",
                                                                  "tension_rate",
                                                                  "tension_dif_max",
                                                                  "damage_length"};

// HJC strength and damage (Holmquist, Johnson & Cook 1993); the constants of 004 Table 4 are
// the examples.
void read_hjc_strength(Reader& r, HjcSpec& h) {
  r.reject({"n", "m", "room_temperature", "melt_temperature", "specific_heat", "taylor_quinney",
            "yield_stress", "tangent_modulus"},
           "by the hjc model (its keys: A, B, N, C, fc, T, S_max, reference_rate, D1, D2, EF_min, "
           "tension_rate, tension_dif_max, damage_length)");
  h.A = r.required("A", dim::none, Bound::NonNegative, "0.79", "normalised cohesion");
  h.B = r.required("B", dim::none, Bound::NonNegative, "1.60", "normalised pressure hardening");
  h.N = r.required("N", dim::none, Bound::Positive, "0.61", "pressure hardening exponent");
  h.C = r.required("C", dim::none, Bound::NonNegative, "0.007", "strain-rate coefficient");
  h.fc = r.required("fc", dim::pressure, Bound::Positive, "48 MPa",
                    "the quasi-static uniaxial compressive strength f'c");
  h.T = r.required("T", dim::pressure, Bound::Positive, "4 MPa", "the tensile strength");
  h.S_max =
      r.required("S_max", dim::none, Bound::Positive, "7.0", "the cap on the normalised strength");
  h.reference_rate = r.quantity("reference_rate", dim::rate, Bound::Positive).value_or(1.0);
  h.D1 = r.required("D1", dim::none, Bound::NonNegative, "0.04", "damage constant");
  h.D2 = r.required("D2", dim::none, Bound::NonNegative, "1.0", "damage exponent");
  h.EF_min = r.required("EF_min", dim::none, Bound::Positive, "0.01",
                        "the least plastic strain to fracture");
  // Opt-in: T rises with the strain rate (docs/scene.md, HJC concrete).
  h.tension_rate = r.choice<HjcSpec::TensionRate>(
                        "tension_rate", {{"none", HjcSpec::TensionRate::None},
                                         {"malvar-ross", HjcSpec::TensionRate::MalvarRoss}})
                       .value_or(HjcSpec::TensionRate::None);
  if (const auto cap = r.quantity("tension_dif_max", dim::none, Bound::Positive)) {
    r.check("tension_dif_max", *cap >= 1.0,
            "must be at least 1 (the factor on T at the quasi-static rate)");
    r.check("tension_dif_max", h.tension_rate != HjcSpec::TensionRate::None,
            "caps the rate law of tension_rate; set tension_rate = \"malvar-ross\" too");
    h.tension_dif_max = *cap;
  }
  // Opt-in: the damage increments averaged over a length (docs/scene.md, HJC concrete).
  h.damage_length = r.quantity("damage_length", dim::length, Bound::Positive).value_or(0.0);
  h.damage_length_loc = r.loc_of("damage_length");
  r.finish();
}

void read_strength(Reader& r, StrengthSpec& s, HjcSpec& h) {
  s.model = r.choice<StrengthModel>("model", {{"elastic", StrengthModel::Elastic},
                                              {"j2", StrengthModel::J2},
                                              {"johnson-cook", StrengthModel::JohnsonCook},
                                              {"bilinear", StrengthModel::Bilinear},
                                              {"hjc", StrengthModel::Hjc}})
                .value_or(StrengthModel::Elastic);
  if (s.model == StrengthModel::Hjc) {
    read_hjc_strength(r, h);
    return;
  }
  r.reject(kHjcStrengthKeys, "by this model (only by \"hjc\")");
  const std::initializer_list<std::string_view> jc_only = {"C",
                                                           "reference_rate",
                                                           "m",
                                                           "room_temperature",
                                                           "melt_temperature",
                                                           "specific_heat",
                                                           "taylor_quinney"};
  const std::initializer_list<std::string_view> bilinear_only = {"yield_stress", "tangent_modulus"};
  if (s.model == StrengthModel::Elastic) {
    r.reject({"A", "B", "n"}, "by the elastic model (set model = \"j2\" or \"johnson-cook\")");
    r.reject(jc_only, "by the elastic model (set model = \"johnson-cook\")");
    r.reject(bilinear_only, "by the elastic model (set model = \"bilinear\")");
    r.finish();
    return;
  }
  if (s.model == StrengthModel::Bilinear) {
    s.A = r.required("yield_stress", dim::pressure, Bound::NonNegative, "1.43 GPa");
    s.tangent_modulus = r.required("tangent_modulus", dim::pressure, Bound::NonNegative,
                                   "14.759 GPa", "the slope after yield, below youngs_modulus");
    r.reject({"A", "B", "n"}, "by the bilinear model (its keys: yield_stress, tangent_modulus)");
    r.reject(jc_only, "by the bilinear model (only by \"johnson-cook\")");
    r.finish();
    return;
  }
  r.reject(bilinear_only, "by the " +
                              std::string(s.model == StrengthModel::J2 ? "j2" : "johnson-cook") +
                              " model (only by \"bilinear\")");
  s.A = r.required("A", dim::pressure, Bound::NonNegative, "157 MPa");
  s.B = r.quantity("B", dim::pressure, Bound::NonNegative).value_or(0.0);
  s.n = r.number("n", Bound::Positive).value_or(1.0);
  if (s.model == StrengthModel::J2) {
    r.reject(jc_only, "by the j2 model (only by \"johnson-cook\")");
    r.finish();
    return;
  }
  s.C = r.number("C", Bound::NonNegative).value_or(0.0);
  s.reference_rate = r.quantity("reference_rate", dim::rate, Bound::Positive).value_or(1.0);
  s.m = r.number("m", Bound::NonNegative).value_or(0.0);
  s.room_temperature =
      r.quantity("room_temperature", dim::temperature, Bound::Positive).value_or(293.0);
  if (s.m > 0) {
    s.melt_temperature = r.required("melt_temperature", dim::temperature, Bound::Positive, "1356 K",
                                    "required when m > 0");
    s.specific_heat = r.required("specific_heat", dim::specific_heat, Bound::Positive,
                                 "383 J/(kg*K)", "required when m > 0");
  } else {
    if (auto v = r.quantity("melt_temperature", dim::temperature, Bound::Positive)) {
      s.melt_temperature = *v;
    }
    if (auto v = r.quantity("specific_heat", dim::specific_heat, Bound::Positive)) {
      s.specific_heat = *v;
    }
  }
  if (r.has("melt_temperature")) {
    r.check("melt_temperature", s.melt_temperature > s.room_temperature,
            "must be above room_temperature (" + format_number(s.room_temperature) + " K)");
  }
  s.taylor_quinney = r.number("taylor_quinney").value_or(0.9);
  r.check("taylor_quinney", s.taylor_quinney >= 0 && s.taylor_quinney <= 1,
          "must be between 0 and 1");
  r.finish();
}

const std::initializer_list<std::string_view> kMieGruneisenKeys = {"c0", "s", "gamma0",
                                                                   "energy_in_expansion"};
const std::initializer_list<std::string_view> kTillotsonKeys = {
    "a", "b", "A", "B", "E0", "E_iv", "E_cv", "alpha", "beta"};
const std::initializer_list<std::string_view> kHjcEosKeys = {
    "P_crush", "mu_crush", "P_lock", "mu_lock", "K1", "K2", "K3"};

// HJC's three-region pressure: elastic to (mu_crush, P_crush), crushing to P_lock, fully dense
// p = K1 mubar + K2 mubar^2 + K3 mubar^3, mubar = (mu - mu_lock) / (1 + mu_lock).
void read_hjc_eos(Reader& r, HjcSpec& h) {
  h.P_crush = r.required("P_crush", dim::pressure, Bound::Positive, "16 MPa");
  h.mu_crush = r.required("mu_crush", dim::none, Bound::Positive, "0.001");
  h.P_lock = r.required("P_lock", dim::pressure, Bound::Positive, "0.80 GPa");
  h.mu_lock = r.required("mu_lock", dim::none, Bound::Positive, "0.10",
                         "the fully dense curve's zero-pressure strain");
  h.K1 = r.required("K1", dim::pressure, Bound::Positive, "85 GPa");
  h.K2 = r.required("K2", dim::pressure, Bound::Any, "-171 GPa");
  h.K3 = r.required("K3", dim::pressure, Bound::Any, "208 GPa");
  r.check("mu_lock", h.mu_lock > h.mu_crush,
          "must be above mu_crush (" + format_number(h.mu_crush) + ")");
  r.check("P_lock", h.P_lock > h.P_crush,
          "must be above P_crush (" + format_number(h.P_crush) + " Pa)");
  // The fully dense curve rises for every mubar > 0: its slope K1 + 2 K2 m + 3 K3 m^2 stays
  // positive (K3 > 0 with K2 >= 0 or K2^2 < 3 K1 K3; K3 = 0 with K2 >= 0).
  const bool rising =
      h.K3 > 0 ? (h.K2 >= 0 || h.K2 * h.K2 < 3.0 * h.K1 * h.K3) : (h.K3 == 0 && h.K2 >= 0);
  r.check("K2", rising,
          "with K1 and K3 the fully dense curve K1 mubar + K2 mubar^2 + K3 mubar^3 must rise for "
          "every mubar > 0 (K3 >= 0, and K2^2 < 3 K1 K3 when K2 < 0)");
}

// Tillotson's constants, each required (docs/eos-tillotson.md derives lead's).
void read_tillotson(Reader& r, TillotsonSpec& t) {
  t.a = r.required("a", dim::none, Bound::NonNegative, "0.5");
  t.b = r.required("b", dim::none, Bound::NonNegative, "1.63");
  t.A = r.required("A", dim::pressure, Bound::Positive, "75.2 GPa");
  t.B = r.required("B", dim::pressure, Bound::Any, "65 GPa");
  t.E0 = r.required("E0", dim::specific_energy, Bound::Positive, "5 MJ/kg");
  t.E_iv = r.required("E_iv", dim::specific_energy, Bound::NonNegative, "3 MJ/kg");
  t.E_cv = r.required("E_cv", dim::specific_energy, Bound::Positive, "13.9 MJ/kg");
  t.alpha = r.required("alpha", dim::none, Bound::NonNegative, "5");
  t.beta = r.required("beta", dim::none, Bound::NonNegative, "5");
  r.check("E_cv", t.E_cv > t.E_iv, "must be above E_iv (" + format_number(t.E_iv) + " J/kg)");
}

void read_eos(Reader& r, EosSpec& e, HjcSpec& h) {
  e.model = r.choice<EosModel>("model", {{"linear", EosModel::Linear},
                                         {"mie-gruneisen", EosModel::MieGruneisen},
                                         {"tillotson", EosModel::Tillotson},
                                         {"hjc", EosModel::Hjc}})
                .value_or(EosModel::Linear);
  if (e.model != EosModel::Hjc) r.reject(kHjcEosKeys, "by this model (only by \"hjc\")");
  if (e.model == EosModel::Hjc) {
    r.reject(kMieGruneisenKeys, "by the hjc model (set model = \"mie-gruneisen\")");
    r.reject(kTillotsonKeys, "by the hjc model (set model = \"tillotson\")");
    read_hjc_eos(r, h);
  } else if (e.model == EosModel::Linear) {
    r.reject(kMieGruneisenKeys, "by the linear model (set model = \"mie-gruneisen\")");
    r.reject(kTillotsonKeys, "by the linear model (set model = \"tillotson\")");
  } else if (e.model == EosModel::Tillotson) {
    r.reject(kMieGruneisenKeys, "by the tillotson model (set model = \"mie-gruneisen\")");
    read_tillotson(r, e.tillotson);
  } else {
    r.reject(kTillotsonKeys, "by the mie-gruneisen model (set model = \"tillotson\")");
    e.c0 = r.required("c0", dim::velocity, Bound::Positive, "3940 m/s");
    e.s = r.required("s", dim::none, Bound::NonNegative, "1.49");
    e.gamma0 = r.required("gamma0", dim::none, Bound::NonNegative, "1.96");
    e.energy_in_expansion = r.boolean("energy_in_expansion").value_or(true);
  }
  r.finish();
}

void read_failure(Reader& r, FailureSpec& f) {
  if (r.table().empty()) {
    r.fail_table("empty table: give plastic_strain, pressure or both (or remove the table)");
  }
  if (auto v = r.number("plastic_strain", Bound::Positive)) f.plastic_strain = *v;
  if (auto v = r.quantity("pressure", dim::pressure, Bound::Negative)) f.pressure = *v;
  r.finish();
}

/// A value outside what any solid has: its plausible range (SI) and the units it was most
/// likely meant in (tried in order).
struct Plausible {
  double lo, hi;                                      ///< SI
  const char* range;                                  ///< the range as the warning prints it
  const char* si;                                     ///< the SI unit
  std::vector<std::pair<const char*, double>> units;  ///< unit and its factor to SI
};

/// Warns (into `warnings`) when v at `at` lies outside p's range, with the likely unit.
void plausible(std::vector<std::string>& warnings, const SourceLoc& at, double v,
               const Plausible& p) {
  if (!(v > 0) || (v >= p.lo && v <= p.hi)) return;
  std::string w = where(at.file, at.line, at.key) + ": " + format_number(v) + " " + p.si + " is " +
                  (v < p.lo ? "below" : "above") + " what any solid has (" + p.range +
                  "); plain numbers are SI";
  for (const auto& [unit, factor] : p.units)
    if (v * factor >= p.lo && v * factor <= p.hi) {
      const std::string key = at.key.substr(at.key.rfind('.') + 1);
      w += ": for " + format_number(v) + " " + unit + " write " + key + " = \"" + format_number(v) +
           " " + unit + "\"";
      break;
    }
  warnings.push_back(w);
}

/// Quantities far outside what any solid has (a modulus typed as 200 for 200 GPa, LS-DYNA's
/// tonnes per mm^3): warnings naming the key and the likely unit.
void check_plausible(const Reader& r, const MaterialSpec& m, const SourceLoc& yield_at,
                     const SourceLoc& c0_at, std::vector<std::string>& warnings) {
  plausible(warnings, r.loc_of("density"), m.density,
            {1, 30000, "1 to 30 000 kg/m^3", "kg/m^3", {{"g/cm^3", 1e3}, {"Mg/mm^3", 1e12}}});
  plausible(warnings, r.loc_of("youngs_modulus"), m.youngs_modulus,
            {1e6, 1.2e12, "1 MPa to 1200 GPa", "Pa", {{"GPa", 1e9}, {"MPa", 1e6}}});
  const StrengthSpec& s = m.strength;
  if (s.model != StrengthModel::Elastic && s.A > m.youngs_modulus)
    warnings.push_back(where(yield_at.file, yield_at.line, yield_at.key) + ": the yield stress " +
                       format_number(s.A) + " Pa is above youngs_modulus (" +
                       format_number(m.youngs_modulus) +
                       " Pa); a yield stress is a small fraction of the modulus: check the "
                       "units of both (plain numbers are SI, Pa)");
  else if (s.model != StrengthModel::Elastic)
    plausible(warnings, yield_at, s.A,
              {1e3, 1e11, "1 kPa to 100 GPa", "Pa", {{"MPa", 1e6}, {"GPa", 1e9}}});
  if (m.eos.model == EosModel::MieGruneisen)
    plausible(warnings, c0_at, m.eos.c0, {100, 20000, "100 to 20 000 m/s", "m/s", {{"km/s", 1e3}}});
}

/// HJC: strength and eos both "hjc" (the damage of one cuts the tension of the other), its
/// elasticity from shear_modulus and K = P_crush / mu_crush (E and nu follow); no failure table
/// (damage is its failure).
void check_hjc(Reader& r, MaterialSpec& m, bool by_shear, double G) {
  const bool s = m.strength.model == StrengthModel::Hjc, e = m.eos.model == EosModel::Hjc;
  if (!s && !e) {
    if (by_shear)
      r.fail("shear_modulus",
             "is for HJC concrete (strength.model and eos.model = \"hjc\"); other materials "
             "give youngs_modulus and poisson_ratio");
    return;
  }
  if (!s || !e)
    r.fail_table(std::string("HJC concrete needs both strength.model and eos.model = \"hjc\" "
                             "(its damage softens the strength and cuts the tension), got ") +
                 (s ? "eos.model" : "strength.model") + " of another model");
  if (!by_shear)
    r.fail_table(
        "missing required key 'shear_modulus' (a pressure, e.g. \"14.86 GPa\"): HJC concrete "
        "gives its shear modulus; its bulk modulus is eos.P_crush / eos.mu_crush");
  if (m.failure.enabled())
    r.fail("failure", "not used by HJC concrete (its damage D is its failure)");
  const double K = m.hjc.K_elastic();
  m.youngs_modulus = 9.0 * K * G / (3.0 * K + G);
  m.poisson_ratio = (3.0 * K - 2.0 * G) / (2.0 * (3.0 * K + G));
}

MaterialSpec read_material(Reader& r, const std::string& name, std::vector<std::string>& warnings) {
  MaterialSpec m;
  m.name = name;
  m.loc = r.loc();
  m.density = r.required("density", dim::density, Bound::Positive, "8930 kg/m^3");
  // HJC concrete gives its shear modulus; its bulk modulus is P_crush / mu_crush (below).
  const bool by_shear = r.has("shear_modulus");
  double G = 0;
  if (by_shear) {
    G = r.required("shear_modulus", dim::pressure, Bound::Positive, "14.86 GPa");
    r.reject({"youngs_modulus", "poisson_ratio"},
             "with shear_modulus (HJC concrete: its bulk modulus is eos.P_crush / eos.mu_crush)");
  } else {
    m.youngs_modulus = r.required("youngs_modulus", dim::pressure, Bound::Positive, "117 GPa");
    m.poisson_ratio = r.required("poisson_ratio", dim::none, Bound::Any, "0.35");
    r.check("poisson_ratio", m.poisson_ratio > -1, "must be above -1");
    r.check("poisson_ratio", m.poisson_ratio < 0.5,
            "must be below 0.5 (incompressible materials are not supported)");
  }
  SourceLoc yield_at, c0_at;
  // The strength table takes the keys of every model; each model's reader refuses the others'.
  std::vector<std::string_view> strength_keys = {"model",
                                                 "A",
                                                 "B",
                                                 "n",
                                                 "C",
                                                 "reference_rate",
                                                 "m",
                                                 "room_temperature",
                                                 "melt_temperature",
                                                 "specific_heat",
                                                 "taylor_quinney",
                                                 "yield_stress",
                                                 "tangent_modulus"};
  strength_keys.insert(strength_keys.end(), kHjcStrengthKeys);
  if (auto t = r.table("strength", strength_keys)) {
    read_strength(*t, m.strength, m.hjc);
    const bool bilinear = m.strength.model == StrengthModel::Bilinear;
    yield_at = t->loc_of(bilinear ? "yield_stress" : "A");
    if (bilinear)
      t->check("tangent_modulus", m.strength.tangent_modulus < m.youngs_modulus,
               "must be below youngs_modulus (" + format_number(m.youngs_modulus) + " Pa)");
  }
  if (auto t = r.table("eos", {"model",    "c0",     "s",       "gamma0", "energy_in_expansion",
                               "a",        "b",      "A",       "B",      "E0",
                               "E_iv",     "E_cv",   "alpha",   "beta",   "P_crush",
                               "mu_crush", "P_lock", "mu_lock", "K1",     "K2",
                               "K3"})) {
    read_eos(*t, m.eos, m.hjc);
    c0_at = t->loc_of("c0");
  }
  if (auto t = r.table("failure", {"plastic_strain", "pressure"})) read_failure(*t, m.failure);
  check_hjc(r, m, by_shear, G);
  r.finish();
  check_plausible(r, m, yield_at, c0_at, warnings);
  return m;
}

}  // namespace

void read_materials(Reader& top, Scene& s) {
  const Doc& doc = top.doc();
  const toml::node* mats = top.get("materials");
  if (!mats) {
    top.fail("materials",
             "missing required table [materials] (one [materials.<name>] table per "
             "material)");
  }
  const auto* mt = mats->as_table();
  if (!mt)
    top.fail("materials", "expected a table of materials ([materials.<name>]), " + got(*mats));
  if (mt->empty()) top.fail("materials", "at least one material is required ([materials.<name>])");
  const Origin mats_origin = top.origin_of(*mats);
  // toml++ tables are sorted by key, so materials are numbered in alphabetical order; this
  // keeps the numbering unchanged when Scene::toml is parsed again.
  for (auto&& [name, node] : *mt) {
    const std::string path = "materials." + std::string(name.str());
    const Origin o = doc.origin(node, mats_origin);
    const auto* t = node.as_table();
    if (!t) {
      throw InputError(doc.where(o, path), "expected a table ([" + path + "]), " + got(node));
    }
    Reader r(doc, *t, path, o,
             {"density", "youngs_modulus", "poisson_ratio", "shear_modulus", "strength", "eos",
              "failure"});
    s.materials.push_back(read_material(r, std::string(name.str()), s.warnings));
  }
}

}  // namespace mpm::scene_toml
