// The field a picture is coloured by.
#include "mpm/post/vtk/render_fields.hpp"

#include <algorithm>
#include <cmath>

#include "mpm/core/error.hpp"
#include "mpm/core/types.hpp"
#include "mpm/post/vtk/frame_columns.hpp"

namespace mpm::vtk_internal {

namespace {

/// Units of the usual columns when the column does not say.
std::string default_unit(const std::string& name) {
  static const std::pair<const char*, const char*> units[] = {
      {"x", "m"},    {"v", "m/s"}, {"m", "kg"},        {"rho", "kg/m^3"},   {"sigma", "Pa"},
      {"e", "J/kg"}, {"T", "K"},   {"pressure", "Pa"}, {"von_mises", "Pa"}, {"speed", "m/s"}};
  for (auto& [n, u] : units)
    if (name == n) return u;
  return "";
}

std::string unit_of(const ColumnInfo& info) {
  return info.unit.empty() ? default_unit(info.name) : info.unit;
}

std::vector<std::string> available_fields(const Frame& frame) {
  std::vector<std::string> names;
  for (auto& c : frame.columns.columns()) names.push_back(c.info().name);
  auto add = [&](const char* n) {
    if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
  };
  const Column* sigma = frame.columns.find("sigma");
  if (sigma && is_voigt(sigma->info())) add("pressure"), add("von_mises");
  if (frame.columns.has("v")) add("speed");
  return names;
}

[[noreturn]] void unknown_field(const Frame& frame, const std::string& field) {
  std::string list;
  for (auto& n : available_fields(frame)) list += (list.empty() ? "" : ", ") + n;
  throw InputError("render", "unknown field '" + field + "'; available fields: " + list);
}

}  // namespace

FieldValues evaluate_field(const Frame& frame, const std::string& field, int component) {
  const std::size_t n = frame.columns.size();
  FieldValues out;
  out.values.resize(n);
  float* v = out.values.data();
  const Column* col = frame.columns.find(field);
  if (!col) {
    const Column* sigma = frame.columns.find("sigma");
    const Column* vel = frame.columns.find("v");
    if ((field == "pressure" || field == "von_mises") && sigma && is_voigt(sigma->info())) {
      if (component > 0)
        throw InputError("render", "'" + field + "' is a scalar; component must be -1 or 0");
      const bool p = field == "pressure";
#pragma omp parallel for schedule(static)
      for (std::size_t i = 0; i < n; ++i) {
        const Sym s = voigt_at(*sigma, i);
        v[i] = float(p ? -trace(s) / 3.0 : von_mises(s));
      }
      out.label = field;
      out.unit = sigma->info().unit.empty() ? "Pa" : sigma->info().unit;
      return out;
    }
    if (field == "speed" && vel && is_floating(vel->info().type)) {
      if (component > 0)
        throw InputError("render", "'speed' is a scalar; component must be -1 or 0");
#pragma omp parallel for schedule(static)
      for (std::size_t i = 0; i < n; ++i) v[i] = float(norm_at(*vel, i));
      out.label = "speed";
      out.unit = unit_of(vel->info());
      return out;
    }
    unknown_field(frame, field);
  }
  const ColumnInfo& info = col->info();
  const int nc = info.components;
  if (component < -1 || component >= nc)
    throw InputError("render", "field '" + field + "' has " + std::to_string(nc) +
                                   " component(s); component " + std::to_string(component) +
                                   " does not exist (use -1 for the magnitude)");
  out.unit = unit_of(info);
  static const char* voigt_names[] = {"xx", "yy", "zz", "yz", "xz", "xy"};
  static const char* axis_names[] = {"x", "y", "z"};
  if (nc == 1) {
    out.label = field;
  } else if (component >= 0) {
    out.label = field + "_" +
                (is_voigt(info) ? voigt_names[component]
                 : nc <= 3      ? axis_names[component]
                                : std::to_string(component));
  } else if (is_voigt(info)) {
    out.label = field == "sigma" ? "von_mises" : "von Mises " + field;
  } else {
    out.label = "|" + field + "|";
  }
  visit_scalar(info.type, [&](auto tag) {
    using T = decltype(tag);
    const T* src = raw<T>(*col);
    if (component >= 0 || nc == 1) {
      const int k = std::max(component, 0);
#pragma omp parallel for schedule(static)
      for (std::size_t i = 0; i < n; ++i) v[i] = float(src[i * nc + k]);
    } else if (is_voigt(info)) {
#pragma omp parallel for schedule(static)
      for (std::size_t i = 0; i < n; ++i) v[i] = float(von_mises(voigt_at(*col, i)));
    } else {
#pragma omp parallel for schedule(static)
      for (std::size_t i = 0; i < n; ++i) {
        double s = 0;
        for (int k = 0; k < nc; ++k) s += double(src[i * nc + k]) * double(src[i * nc + k]);
        v[i] = float(std::sqrt(s));
      }
    }
  });
  return out;
}

}  // namespace mpm::vtk_internal
