#pragma once
/// What each material went through in a run, sampled at the frames mpm-run writes: the most
/// tensile and most compressive pressure, the largest speed, plastic strain and temperature.
/// Printed at the end of the run, with a warning where a material that has no failure model
/// carried a tension far past what any solid spalls at (issue 26: a plate at -12.6 GPa).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "mpm/core/columns.hpp"
#include "mpm/scene/particles.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm {

class MaterialExtremes {
 public:
  /// Tension above this fraction of a material's bulk modulus is far past a plausible spall
  /// strength: measured spall strengths of metals are 0.5-2% of K (aluminium about 1.2 GPa of
  /// 76 GPa, copper 1.5-2 of 140, steels 2-4 of 160), the ideal lattice strength some 10%.
  static constexpr double kSpallFraction = 0.05;

  explicit MaterialExtremes(const Scene& scene) : scene_(scene), rows_(scene.materials.size()) {}

  /// Takes the extremes of the particles now (at a frame).
  void sample(const ColumnStore& p, double time) {
    const Column* mc = p.find(col::material);
    const Column* sc = p.find(col::sigma);
    const Column* vc = p.find(col::v);
    if (!mc || !sc || !vc) return;
    ++samples_;
    const auto* mat = reinterpret_cast<const std::uint8_t*>(mc->data());
    const auto* sigma = reinterpret_cast<const double*>(sc->data());
    const auto* v = reinterpret_cast<const double*>(vc->data());
    const int dv = vc->info().components;
    const double* eps = p.get<double>(col::eps_p);  // nullptr when no material needs it
    const double* T = p.get<double>(col::T);
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (mat[i] >= rows_.size()) continue;  // rigid particles
      Row& r = rows_[mat[i]];
      const double* s = sigma + 6 * i;
      const double pressure = -(s[0] + s[1] + s[2]) / 3;
      if (pressure < r.tension) r.tension = pressure, r.tension_time = time;
      r.compression = std::max(r.compression, pressure);
      double v2 = 0;
      for (int a = 0; a < dv; ++a) v2 += v[i * dv + a] * v[i * dv + a];
      r.speed = std::max(r.speed, std::sqrt(v2));
      if (eps) r.eps_p = std::max(r.eps_p, eps[i]);
      if (T) r.T = std::max(r.T, T[i]);
      r.seen = true;
    }
  }

  /// The table and the warnings, on `out`.
  void report(std::FILE* out) const {
    if (samples_ == 0) return;
    std::fprintf(out,
                 "mpm-run: material extremes over the %d frames written (pressure > 0 in "
                 "compression):\n  %-14s %14s %14s %12s %8s %10s\n",
                 samples_, "material", "min p (GPa)", "max p (GPa)", "speed (m/s)", "eps_p",
                 "T (K)");
    for (std::size_t k = 0; k < rows_.size(); ++k) {
      const Row& r = rows_[k];
      if (!r.seen) continue;
      char T[32] = "-";
      if (r.T > -std::numeric_limits<double>::infinity()) std::snprintf(T, sizeof T, "%.0f", r.T);
      std::fprintf(out, "  %-14s %14.4g %14.4g %12.4g %8.3g %10s\n",
                   scene_.materials[k].name.c_str(), r.tension / 1e9, r.compression / 1e9, r.speed,
                   r.eps_p, T);
    }
    for (std::size_t k = 0; k < rows_.size(); ++k) {
      const Row& r = rows_[k];
      const MaterialSpec& m = scene_.materials[k];
      const double K = m.bulk_modulus();
      if (!r.seen || m.failure.enabled() || !(K > 0) || -r.tension <= kSpallFraction * K) continue;
      std::fprintf(out,
                   "mpm-run: warning: material '%s' has no failure model and carried %.3g GPa "
                   "of tension (t = %.4g s), %.0f%% of its bulk modulus, far past what solids "
                   "spall at (about 1%% of it): give [materials.%s.failure] (pressure = \"-1.5 "
                   "GPa\", the spall strength) or check the result\n",
                   m.name.c_str(), -r.tension / 1e9, r.tension_time, -100 * r.tension / K,
                   m.name.c_str());
    }
  }

 private:
  struct Row {
    double tension = 0;       ///< Pa, the most negative pressure
    double tension_time = 0;  ///< s, when
    double compression = 0;   ///< Pa, the largest pressure
    double speed = 0, eps_p = 0;
    double T = -std::numeric_limits<double>::infinity();
    bool seen = false;
  };
  const Scene& scene_;
  std::vector<Row> rows_;
  int samples_ = 0;
};

}  // namespace mpm
