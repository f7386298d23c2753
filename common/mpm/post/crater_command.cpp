// mpm-post crater: the crater of a target body and how deep each body went, as text or JSON.
#include <cmath>
#include <cstdio>
#include <optional>

#include "mpm/core/error.hpp"
#include "mpm/post/arguments.hpp"
#include "mpm/post/command_io.hpp"
#include "mpm/post/commands.hpp"
#include "mpm/post/crater.hpp"
#include "mpm/post/json.hpp"

namespace mpm {

namespace {

void print_crater_json(const CraterResult& r) {
  JsonWriter j;
  j.begin_object().key("time").number(r.time).key("target").string(r.target);
  j.key("axis").string(std::string(1, "xyz"[r.axis])).key("direction").integer(r.direction);
  j.key("axis_point").numbers({r.axis_point.x(), r.axis_point.y(), r.axis_point.z()});
  j.key("surface").number(r.surface).key("thickness").number(r.thickness);
  j.key("spacing").number(r.spacing).key("perforated").boolean(r.perforated);
  j.key("depth").number(r.depth).key("diameter").number(r.diameter);
  j.key("penetration").begin_object();
  for (const Penetration& p : r.penetration) j.key(p.body).number(p.depth);
  j.end_object();
  j.key("profile").begin_array();
  for (const auto& [rho, zeta] : r.profile) j.numbers({rho, zeta});
  j.end_array();
  j.key("particles").integer(r.particles).key("symmetry");
  write_symmetry_json(j, r.symmetry);
  j.end_object();
  std::printf("%s\n", j.text().c_str());
}

void print_crater_text(const CraterResult& r) {
  const char ax = "xyz"[r.axis];
  std::printf(
      "Crater in '%s' at t = %.4g us: impact along %s%c, the crater's axis through the "
      "projectile's initial centre (%.4g, %.4g, %.4g) mm\n",
      r.target.c_str(), r.time * 1e6, r.direction > 0 ? "+" : "-", ax, r.axis_point.x() * 1e3,
      r.axis_point.y() * 1e3, r.axis_point.z() * 1e3);
  if (!r.symmetry.describe().empty()) std::printf("  %s\n", r.symmetry.describe().c_str());
  std::printf(
      "  original front surface %c = %.4g mm, thickness %.4g mm, particle spacing %.4g mm\n", ax,
      r.surface * 1e3, r.thickness * 1e3, r.spacing * 1e3);
  if (r.perforated)
    std::printf(
        "  perforated: hole diameter = %.3f mm (the narrowest through the thickness), depth = "
        "the thickness %.3f mm\n",
        r.diameter * 1e3, r.depth * 1e3);
  else
    std::printf("  depth = %.3f mm, diameter = %.3f mm (at the original front surface)\n",
                r.depth * 1e3, r.diameter * 1e3);
  for (const Penetration& p : r.penetration)
    std::printf("  penetration of '%s' below the original surface: %.3f mm%s\n", p.body.c_str(),
                p.depth * 1e3, p.depth > r.thickness ? " (past the rear face)" : "");
}

}  // namespace

int post_crater(const CraterArgs& a) {
  const std::string& path = a.input;
  CraterOptions opt;
  opt.impact.target = a.target;
  opt.impact.projectile = a.projectile;
  if (!a.axis.empty()) opt.impact.axis = option_axis(a.axis, "--axis");
  std::optional<double> at;
  if (!a.time.empty()) at = option_quantity(a.time, dim::time, "--time");
  std::optional<Scene> scene;
  std::optional<CraterMeter> meter;
  std::optional<Frame> chosen;
  double best = 1e300;
  std::size_t frames = 0;
  StreamVisitor v;
  v.scene = [&](const std::string& t) {
    scene = scene_of(t, path);
    opt.symmetry = measure_symmetry(a.symmetry, *scene);
  };
  v.frame = [&](Frame&& f) {
    ++frames;
    if (!scene) throw StreamError(input_name(path), "a frame comes before the scene record");
    if (!meter) meter.emplace(*scene, f, opt);
    const double d = at ? std::abs(f.time - *at) : 0.0;
    if (!at || d <= best) best = d, chosen = std::move(f);
  };
  const StreamSummary s = read_stream(path, v);
  if (!chosen) {
    std::fprintf(stderr, "mpm-post: error: %s holds no frame to measure\n",
                 input_name(path).c_str());
    return kExitBadInput;
  }
  const CraterResult r = meter->measure(*chosen);
  if (a.json)
    print_crater_json(r);
  else
    print_crater_text(r);
  std::fflush(stdout);
  return conclude(path, s, frames);
}

}  // namespace mpm
