// mpm-post taylor and debris: the measures of post.hpp on a result stream, as text or JSON.
#include <cmath>
#include <cstdio>
#include <optional>

#include "mpm/core/error.hpp"
#include "mpm/post/arguments.hpp"
#include "mpm/post/column_value.hpp"
#include "mpm/post/command_io.hpp"
#include "mpm/post/commands.hpp"
#include "mpm/post/json.hpp"
#include "mpm/post/post.hpp"
#include "mpm/post/symmetry.hpp"

namespace mpm {

namespace {

/// An optional length option: empty text gives none.
std::optional<double> optional_length(const std::string& text, const std::string& option) {
  if (text.empty()) return std::nullopt;
  return option_quantity(text, dim::length, option);
}

void print_taylor_json(const TaylorResult& r, std::optional<double> eL, std::optional<double> eD) {
  JsonWriter j;
  j.begin_object().key("time").number(r.time).key("measure").string(r.measure);
  j.key("L").number(r.L).key("D").number(r.D).key("L0").number(r.L0).key("D0").number(r.D0);
  j.key("axis").string(std::string(1, "xyz"[r.axis])).key("wall").number(r.wall);
  j.key("spacing").number(r.spacing).key("particles").integer(r.particles);
  j.key("D_min").number(r.D_min).key("D_max").number(r.D_max);
  j.key("D_radius").number(r.D_radius);
  j.key("symmetry");
  write_symmetry_json(j, r.symmetry);
  if (eL) j.key("expected_L").number(*eL).key("error_L").number(r.L / *eL - 1);
  if (eD) j.key("expected_D").number(*eD).key("error_D").number(r.D / *eD - 1);
  j.end_object();
  std::printf("%s\n", j.text().c_str());
}

void print_taylor_text(const TaylorResult& r, std::optional<double> eL, std::optional<double> eD) {
  std::printf("Taylor bar at t = %.4g us (%s; axis %c, wall at %.4g mm, %zu particles)\n",
              r.time * 1e6,
              r.measure == "centres" ? "particle centres" : "surface: centres + half a spacing",
              "xyz"[r.axis], r.wall * 1e3, r.particles);
  if (!r.symmetry.describe().empty()) std::printf("  %s\n", r.symmetry.describe().c_str());
  std::printf("  L = %.3f mm", r.L * 1e3);
  if (eL) std::printf("   expected %.3f mm, %+.2f%%", *eL * 1e3, 100 * (r.L / *eL - 1));
  std::printf("   (L0 = %.3f mm, L/L0 = %.4f)\n", r.L0 * 1e3, r.L / r.L0);
  std::printf("  D = %.3f mm", r.D * 1e3);
  if (eD) std::printf("   expected %.3f mm, %+.2f%%", *eD * 1e3, 100 * (r.D / *eD - 1));
  std::printf("   (D0 = %.3f mm, D/D0 = %.4f)\n", r.D0 * 1e3, r.D / r.D0);
  if (r.D_max > r.D_min)
    std::printf(
        "      mean caliper width; %.3f to %.3f mm by direction, twice the largest "
        "radius %.3f mm\n",
        r.D_min * 1e3, r.D_max * 1e3, r.D_radius * 1e3);
}

/// The particles that left the domain by the measured frame's time (ESCP records), and those
/// of them that left downstream of the plane: part of the cloud, gone from the frame.
struct EscapedCount {
  std::size_t n = 0, behind = 0;
  double mass = 0, mass_behind = 0;  ///< kg (whole rings in axisymmetry)
};

EscapedCount count_escaped(const std::vector<Frame>& records, const DebrisResult& r,
                           double factor) {
  EscapedCount c;
  for (const Frame& f : records) {
    const Column *x = f.columns.find("x"), *m = f.columns.find("m"), *t = f.columns.find("t_exit");
    if (!x || !m || !t) continue;
    for (std::size_t i = 0; i < f.columns.size(); ++i) {
      if (column_value(*t, i, 0) > r.time * (1 + 1e-12)) continue;
      const double m_p = factor * column_value(*m, i, 0);
      const bool behind = r.direction * (column_value(*x, i, r.axis) - r.plane) > 0;
      ++c.n;
      c.mass += m_p;
      if (behind) ++c.behind, c.mass_behind += m_p;
    }
  }
  return c;
}

void print_debris_json(const DebrisResult& r, std::optional<double> ef, std::optional<double> ew,
                       const std::optional<EscapedCount>& esc) {
  JsonWriter j;
  j.begin_object().key("time").number(r.time).key("axis").string(std::string(1, "xyz"[r.axis]));
  j.key("direction").integer(r.direction).key("plane").number(r.plane);
  j.key("face").string(r.face == DebrisFace::Impact ? "impact" : "rear");
  j.key("face_plane").number(r.face_plane);
  j.key("cloud_particles").integer(r.cloud).key("particles").integer(r.total);
  j.key("percentile").number(r.percentile).key("front").number(r.front);
  j.key("width").number(r.width).key("front_max").number(r.front_max);
  j.key("front_p99").number(r.front_p99).key("front_p99_5").number(r.front_p995);
  j.key("front_p99_9").number(r.front_p999).key("width_max").number(r.width_max);
  j.key("width_p99").number(r.width_p99).key("width_p99_5").number(r.width_p995);
  j.key("width_p99_9").number(r.width_p999);
  j.key("link").number(r.link).key("min_fragment").integer(r.min_fragment);
  j.key("fragments").integer(r.fragments).key("single_particle_fragments").integer(r.singles);
  j.key("largest_fragment").integer(r.largest).key("counted_particles").integer(r.counted);
  j.key("percentiles_of").string(r.by_mass ? "mass" : "particles");
  j.key("symmetry");
  write_symmetry_json(j, r.symmetry);
  if (ef) j.key("expected_front").number(*ef).key("error_front").number(r.front / *ef - 1);
  if (ew) j.key("expected_width").number(*ew).key("error_width").number(r.width / *ew - 1);
  if (esc) {
    j.key("escaped_particles").integer(esc->n).key("escaped_mass").number(esc->mass);
    j.key("escaped_behind_plane").integer(esc->behind);
    j.key("escaped_behind_plane_mass").number(esc->mass_behind);
  }
  j.end_object();
  std::printf("%s\n", j.text().c_str());
}

void print_debris_text(const DebrisResult& r, std::optional<double> ef, std::optional<double> ew) {
  std::printf(
      "Debris cloud at t = %.4g us: %zu of %zu particles behind the plane %c = %.3f mm "
      "(the target's rear face), impact along %s%c\n",
      r.time * 1e6, r.cloud, r.total, "xyz"[r.axis], r.plane * 1e3, r.direction > 0 ? "+" : "-",
      "xyz"[r.axis]);
  if (!r.symmetry.describe().empty()) std::printf("  %s\n", r.symmetry.describe().c_str());
  if (r.face == DebrisFace::Impact)
    std::printf("  front measured from the target's impact face %c = %.3f mm\n", "xyz"[r.axis],
                r.face_plane * 1e3);
  std::printf(
      "  fragments (particles closer than %.3g mm linked): %zu, %zu of them single particles, "
      "the "
      "largest %zu particles\n",
      r.link * 1e3, r.fragments, r.singles, r.largest);
  if (r.min_fragment > 1)
    std::printf("  counted: the %zu particles of fragments of at least %zu particles\n", r.counted,
                r.min_fragment);
  std::printf("  %-8s %10s %10s %10s %10s\n", "mm", "max", "p99", "p99.5", "p99.9");
  std::printf("  %-8s %10.1f %10.1f %10.1f %10.1f\n", "front", r.front_max * 1e3, r.front_p99 * 1e3,
              r.front_p995 * 1e3, r.front_p999 * 1e3);
  std::printf("  %-8s %10.1f %10.1f %10.1f %10.1f\n", "width", r.width_max * 1e3, r.width_p99 * 1e3,
              r.width_p995 * 1e3, r.width_p999 * 1e3);
  std::printf("  front = %.1f mm", r.front * 1e3);
  if (ef) std::printf(" (expected %.1f mm, %+.1f%%)", *ef * 1e3, 100 * (r.front / *ef - 1));
  std::printf(", width = %.1f mm", r.width * 1e3);
  if (ew) std::printf(" (expected %.1f mm, %+.1f%%)", *ew * 1e3, 100 * (r.width / *ew - 1));
  std::printf("   [%g-th percentile of the cloud's %s]\n", r.percentile,
              r.by_mass ? "mass" : "particles");
}

}  // namespace

int post_taylor(const TaylorArgs& a) {
  const std::string& path = a.input;
  std::optional<TaylorMeter> meter;
  std::optional<TaylorResult> first, last;
  std::size_t frames = 0;
  TaylorOptions opt;
  opt.body = a.body;
  opt.surface = a.surface;
  if (!a.axis.empty()) opt.axis = option_axis(a.axis, "--axis");
  if (!a.wall.empty()) opt.wall = option_quantity(a.wall, dim::length, "--wall");
  StreamVisitor v;
  v.scene = [&](const std::string& t) {
    const Scene scene = scene_of(t, path);
    opt.symmetry = measure_symmetry(a.symmetry, scene);
    meter.emplace(scene, opt);
  };
  v.frame = [&](Frame&& f) {
    ++frames;
    if (!meter) throw StreamError(input_name(path), "a frame comes before the scene record");
    const TaylorResult r = meter->measure(f);
    if (!first) first = r;
    last = r;
  };
  const StreamSummary s = read_stream(path, v);
  if (!last) {
    std::fprintf(stderr, "mpm-post: error: %s holds no frame to measure%s%s\n",
                 input_name(path).c_str(), s.damage.empty() ? "" : ": ", s.damage.c_str());
    return kExitBadInput;
  }
  TaylorResult r = *last;
  r.L0 = first->L;
  r.D0 = first->D;
  const std::optional<double> eL = optional_length(a.expect_L, "--expect-L");
  const std::optional<double> eD = optional_length(a.expect_D, "--expect-D");
  if (a.json)
    print_taylor_json(r, eL, eD);
  else
    print_taylor_text(r, eL, eD);
  std::fflush(stdout);
  return conclude(path, s, frames);
}

int post_debris(const DebrisArgs& a) {
  const std::string& path = a.input;
  DebrisOptions opt;
  opt.target = a.target;
  opt.projectile = a.projectile;
  opt.percentile = a.percentile;
  opt.min_fragment = a.min_fragment;
  if (!a.link.empty()) opt.link = option_quantity(a.link, dim::length, "--link");
  if (!a.axis.empty()) opt.axis = option_axis(a.axis, "--axis");
  if (!a.plane.empty()) opt.plane = option_quantity(a.plane, dim::length, "--plane");
  opt.face = a.face == "impact" ? DebrisFace::Impact : DebrisFace::Rear;
  std::optional<double> at;
  if (!a.time.empty()) at = option_quantity(a.time, dim::time, "--time");
  std::optional<Scene> scene;
  std::optional<DebrisMeter> meter;
  std::optional<DebrisResult> chosen;
  double best = 1e300;
  std::size_t frames = 0;
  std::vector<Frame> escaped;
  StreamVisitor v;
  v.scene = [&](const std::string& t) {
    scene = scene_of(t, path);
    opt.symmetry = measure_symmetry(a.symmetry, *scene);
  };
  if (a.escaped) v.escapes = [&](Frame&& f) { escaped.push_back(std::move(f)); };
  v.frame = [&](Frame&& f) {
    ++frames;
    if (!scene) throw StreamError(input_name(path), "a frame comes before the scene record");
    if (!meter) meter.emplace(*scene, f, opt);
    const double d = at ? std::abs(f.time - *at) : 0.0;
    if (!at || d <= best) {
      best = d;
      chosen = meter->measure(f);
    }
  };
  const StreamSummary s = read_stream(path, v);
  if (!chosen) {
    std::fprintf(stderr, "mpm-post: error: %s holds no frame to measure\n",
                 input_name(path).c_str());
    return kExitBadInput;
  }
  const std::optional<double> ef = optional_length(a.expect_front, "--expect-front");
  const std::optional<double> ew = optional_length(a.expect_width, "--expect-width");
  std::optional<EscapedCount> esc;
  if (a.escaped) esc = count_escaped(escaped, *chosen, scene->measure_factor());
  if (a.json) {
    print_debris_json(*chosen, ef, ew, esc);
  } else {
    print_debris_text(*chosen, ef, ew);
    if (esc)
      std::printf(
          "  escaped (left the domain by then): %zu particles, %.4g kg; %zu of them, %.4g kg, "
          "behind the plane\n",
          esc->n, esc->mass, esc->behind, esc->mass_behind);
  }
  std::fflush(stdout);
  return conclude(path, s, frames);
}

}  // namespace mpm
