// mpm-post: what users report from a result stream.
//   mpm-post summary run.mpm            mpm-post history run.mpm -o history.csv
//   mpm-post vtk run.mpm -o out/        mpm-post taylor run.mpm --json
//   mpm-post particles run.mpm --columns x,sigma -o last.csv
//   mpm-post render run.mpm -o bar.png --field eps_p
//   mpm-post profile run.mpm --field sigma --component xx --time 9us   (CSV, or --json)
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>

#include "mpm/core/cli.hpp"
#include "mpm/core/error.hpp"
#include "mpm/core/units.hpp"
#include "mpm/core/version.hpp"
#include "mpm/post/post.hpp"
#include "mpm/post/profile.hpp"
#include "mpm/post/vtk/vtk_output.hpp"
#include "mpm/stream/grid_record.hpp"
#include "mpm/stream/stream.hpp"

namespace {

using namespace mpm;

std::string input_name(const std::string& path) {
  return path == "-" ? "stdin" : path;
}

/// What every subcommand says after reading: damage (exit 2), an unfinished or failed run.
int conclude(const std::string& path, const StreamSummary& s, std::size_t frames_used) {
  if (!s.damage.empty()) {
    std::fprintf(stderr, "mpm-post: error: %s; used the %zu frame(s) before it\n", s.damage.c_str(),
                 frames_used);
    return kExitBadInput;
  }
  if (!s.ended) {
    std::fprintf(stderr,
                 "mpm-post: error: %s: the stream ends without an end record: its producer stopped "
                 "before finishing (killed, or still running); used the %zu frame(s) it holds\n",
                 input_name(path).c_str(), frames_used);
    return kExitBadInput;
  }
  if (s.end_status != 0) {
    std::fprintf(stderr, "mpm-post: warning: the run ended with status %d: %s\n", s.end_status,
                 s.end_message.c_str());
    return s.end_status;
  }
  return kExitOk;
}

Scene scene_of(const std::string& text, const std::string& path) {
  if (text.empty()) throw StreamError(input_name(path), "the stream holds no scene record");
  return parse_scene(text, input_name(path) + " (scene)", "", {});
}

std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  char b[40];
  std::snprintf(b, sizeof b, "%.10g", v);
  return b;
}

std::string json_string(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\')
      o += '\\', o += c;
    else if (c == '\n')
      o += "\\n";
    else if (static_cast<unsigned char>(c) < 0x20)
      o += ' ';
    else
      o += c;
  }
  return o + "\"";
}

/// An axis option: "x", "y" or "z" to 0, 1, 2.
int axis_of(const std::string& text) {
  if (text != "x" && text != "y" && text != "z")
    throw InputError("--axis", "expected x, y or z, got '" + text + "'");
  return text[0] - 'x';
}

/// A command-line quantity: "16.2 mm", or a plain number in SI units (as in scene files).
double quantity(const std::string& text, const Dimension& dim, const std::string& option) {
  try {
    std::size_t used = 0;
    try {
      const double v = std::stod(text, &used);
      if (used == text.size()) return v;
    } catch (const std::logic_error&) {
    }
    const Quantity q = parse_quantity(text);
    if (!(q.dim == dim)) throw std::invalid_argument("expected " + describe(dim));
    return q.value;
  } catch (const std::invalid_argument& e) {
    throw InputError(option, std::string(e.what()) + " in '" + text + "'");
  }
}

// summary ---------------------------------------------------------------------------------
int cmd_summary(const std::string& path, bool json) {
  std::string scene_text;
  std::vector<std::string> infos;
  struct F {
    std::int64_t step;
    double time;
    std::size_t n;
    std::uint32_t flags;
  };
  std::vector<F> frames;
  std::size_t hist_rows = 0;
  std::vector<std::string> hist_names;
  StreamVisitor v;
  v.scene = [&](const std::string& t) { scene_text = t; };
  v.info = [&](const std::string& t) { infos.push_back(t); };
  v.frame = [&](Frame&& f) { frames.push_back({f.step, f.time, f.columns.size(), f.flags}); };
  v.history = [&](HistoryBlock&& h) {
    hist_rows += h.rows();
    if (hist_names.empty()) hist_names = h.names;
  };
  const StreamSummary s = read_stream(path, v);
  std::string title;
  int dim = 0;
  if (!scene_text.empty()) {
    const Scene sc = scene_of(scene_text, path);
    title = sc.title;
    dim = sc.dimension;
  }
  if (json) {
    std::printf("{\"input\": %s, \"title\": %s, \"dimension\": %d, \"frames\": [",
                json_string(input_name(path)).c_str(), json_string(title).c_str(), dim);
    for (std::size_t k = 0; k < frames.size(); ++k)
      std::printf("%s{\"step\": %lld, \"time\": %s, \"particles\": %zu}", k ? ", " : "",
                  (long long)frames[k].step, json_number(frames[k].time).c_str(), frames[k].n);
    std::printf(
        "], \"history_rows\": %zu, \"ended\": %s, \"status\": %d, \"message\": %s, "
        "\"damage\": %s}\n",
        hist_rows, s.ended ? "true" : "false", s.end_status, json_string(s.end_message).c_str(),
        json_string(s.damage).c_str());
  } else {
    std::printf("stream: %s\n", input_name(path).c_str());
    if (!title.empty()) std::printf("scene: %s (%dD)\n", title.c_str(), dim);
    std::printf("frames: %zu\n", frames.size());
    std::printf("  %8s %14s %12s\n", "step", "time (us)", "particles");
    for (const auto& f : frames)
      std::printf("  %8lld %14.4f %12zu%s\n", (long long)f.step, f.time * 1e6, f.n,
                  (f.flags & kFrameModel)   ? "  (model)"
                  : (f.flags & kFrameFinal) ? "  (final)"
                                            : "");
    std::printf("history: %zu rows", hist_rows);
    if (!hist_names.empty()) {
      std::printf(" of");
      for (auto& n : hist_names) std::printf(" %s", n.c_str());
    }
    std::printf("\nend: %s\n",
                s.ended ? ("status " + std::to_string(s.end_status) + ", " + s.end_message).c_str()
                        : "missing (the producer stopped early or is still running)");
    if (!s.damage.empty()) std::printf("damage: %s\n", s.damage.c_str());
  }
  if (!s.damage.empty()) {
    std::fprintf(stderr, "mpm-post: error: %s\n", s.damage.c_str());
    return kExitBadInput;
  }
  return kExitOk;
}

// history ---------------------------------------------------------------------------------
int cmd_history(const std::string& path, const std::string& out,
                const std::vector<std::string>& cols) {
  std::vector<std::string> names;
  std::vector<int> pick;
  std::FILE* f = out == "-" ? stdout : std::fopen(out.c_str(), "w");
  if (!f) throw IoError("cannot write '" + out + "': " + std::strerror(errno));
  std::size_t frames = 0;
  StreamVisitor v;
  v.want_frames = false;
  v.frame = [&](Frame&&) { ++frames; };
  v.history = [&](HistoryBlock&& h) {
    if (names.empty()) {
      names = h.names;
      if (cols.empty()) {
        for (std::size_t k = 0; k < names.size(); ++k) pick.push_back(int(k));
      } else {
        for (const auto& c : cols) {
          auto it = std::find(names.begin(), names.end(), c);
          if (it == names.end()) {
            std::string known;
            for (auto& n : names) known += (known.empty() ? "" : ", ") + n;
            throw InputError("--columns",
                             "unknown history column '" + c + "' (known: " + known + ")");
          }
          pick.push_back(int(it - names.begin()));
        }
      }
      for (std::size_t k = 0; k < pick.size(); ++k)
        std::fprintf(f, "%s%s", k ? "," : "", names[pick[k]].c_str());
      std::fprintf(f, "\n");
    }
    const std::size_t nc = h.names.size();
    for (std::size_t r = 0; r < h.rows(); ++r) {
      for (std::size_t k = 0; k < pick.size(); ++k)
        std::fprintf(f, "%s%.10g", k ? "," : "", h.values[r * nc + pick[k]]);
      std::fprintf(f, "\n");
    }
  };
  const StreamSummary s = read_stream(path, v);
  if (f != stdout)
    std::fclose(f);
  else
    std::fflush(stdout);
  return conclude(path, s, frames);
}

// vtk -------------------------------------------------------------------------------------
int cmd_vtk(const std::string& path, const std::string& dir, const std::string& name, int every) {
  std::error_code ec;
  if (std::filesystem::exists(dir, ec) && !std::filesystem::is_directory(dir, ec))
    throw InputError("-o " + dir,
                     "exists and is not a directory (vtk writes a directory of .vtu "
                     "files and a .pvd series)");
  std::filesystem::create_directories(dir, ec);
  if (ec) throw IoError("cannot create the directory '" + dir + "': " + ec.message());
  std::vector<std::pair<double, std::string>> entries;
  std::size_t index = 0;
  StreamVisitor v;
  v.frame = [&](Frame&& f) {
    if (index++ % std::size_t(every) != 0 && !(f.flags & kFrameFinal)) return;
    const int dim = f.columns.at("x").info().components;
    char file[256];
    std::snprintf(file, sizeof file, "%s_%04zu.vtu", name.c_str(), entries.size());
    write_vtu(f, dim, (std::filesystem::path(dir) / file).string());
    entries.emplace_back(f.time, file);
    write_pvd(entries, (std::filesystem::path(dir) / (name + ".pvd")).string());
  };
  // Graded grids: each GRID record as <name>_grid_NNNN.vtu, listed by time in <name>_grid.pvd.
  std::vector<std::pair<double, std::string>> grids;
  v.grid = [&](std::vector<std::byte>&& payload) {
    GridMesh mesh;
    try {
      mesh = decode_grid(payload);
    } catch (const StreamError& e) {
      throw StreamError(input_name(path), e.message());
    }
    char file[256];
    std::snprintf(file, sizeof file, "%s_grid_%04zu.vtu", name.c_str(), grids.size());
    write_grid_vtu(mesh, (std::filesystem::path(dir) / file).string());
    grids.emplace_back(mesh.time, file);
    write_pvd(grids, (std::filesystem::path(dir) / (name + "_grid.pvd")).string());
  };
  const StreamSummary s = read_stream(path, v);
  std::fprintf(stderr, "mpm-post: wrote %zu frame(s) and %s\n", entries.size(),
               (std::filesystem::path(dir) / (name + ".pvd")).string().c_str());
  if (!grids.empty())
    std::fprintf(stderr, "mpm-post: wrote %zu graded grid(s) and %s (cell field 'level')\n",
                 grids.size(),
                 (std::filesystem::path(dir) / (name + "_grid.pvd")).string().c_str());
  return conclude(path, s, index);
}

// taylor ----------------------------------------------------------------------------------
struct TaylorArgs {
  std::string body, axis, wall, expect_L, expect_D;
  bool surface = false, json = false;
};

int cmd_taylor(const std::string& path, const TaylorArgs& a) {
  std::string scene_text;
  std::optional<TaylorMeter> meter;
  std::optional<TaylorResult> first, last;
  std::size_t frames = 0;
  TaylorOptions opt;
  opt.body = a.body;
  opt.surface = a.surface;
  if (!a.axis.empty()) opt.axis = axis_of(a.axis);
  if (!a.wall.empty()) opt.wall = quantity(a.wall, dim::length, "--wall");
  StreamVisitor v;
  v.scene = [&](const std::string& t) {
    scene_text = t;
    meter.emplace(scene_of(t, path), opt);
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
  std::optional<double> eL, eD;
  if (!a.expect_L.empty()) eL = quantity(a.expect_L, dim::length, "--expect-L");
  if (!a.expect_D.empty()) eD = quantity(a.expect_D, dim::length, "--expect-D");
  if (a.json) {
    std::printf(
        "{\"time\": %s, \"measure\": %s, \"L\": %s, \"D\": %s, \"L0\": %s, \"D0\": %s, "
        "\"axis\": \"%c\", \"wall\": %s, \"spacing\": %s, \"particles\": %zu",
        json_number(r.time).c_str(), json_string(r.measure).c_str(), json_number(r.L).c_str(),
        json_number(r.D).c_str(), json_number(r.L0).c_str(), json_number(r.D0).c_str(),
        "xyz"[r.axis], json_number(r.wall).c_str(), json_number(r.spacing).c_str(), r.particles);
    std::printf(", \"D_min\": %s, \"D_max\": %s, \"D_radius\": %s", json_number(r.D_min).c_str(),
                json_number(r.D_max).c_str(), json_number(r.D_radius).c_str());
    if (eL)
      std::printf(", \"expected_L\": %s, \"error_L\": %s", json_number(*eL).c_str(),
                  json_number(r.L / *eL - 1).c_str());
    if (eD)
      std::printf(", \"expected_D\": %s, \"error_D\": %s", json_number(*eD).c_str(),
                  json_number(r.D / *eD - 1).c_str());
    std::printf("}\n");
  } else {
    std::printf("Taylor bar at t = %.4g us (%s; axis %c, wall at %.4g mm, %zu particles)\n",
                r.time * 1e6,
                r.measure == "centres" ? "particle centres" : "surface: centres + half a spacing",
                "xyz"[r.axis], r.wall * 1e3, r.particles);
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
  std::fflush(stdout);
  return conclude(path, s, frames);
}

// debris ----------------------------------------------------------------------------------
struct DebrisArgs {
  std::string time, axis, plane, target, projectile, expect_front, expect_width, link;
  double percentile = 99.5;
  std::size_t min_fragment = 1;
  bool json = false;
};

int cmd_debris(const std::string& path, const DebrisArgs& a) {
  DebrisOptions opt;
  opt.target = a.target;
  opt.projectile = a.projectile;
  opt.percentile = a.percentile;
  opt.min_fragment = a.min_fragment;
  if (!a.link.empty()) opt.link = quantity(a.link, dim::length, "--link");
  if (!a.axis.empty()) opt.axis = axis_of(a.axis);
  if (!a.plane.empty()) opt.plane = quantity(a.plane, dim::length, "--plane");
  std::optional<double> at;
  if (!a.time.empty()) at = quantity(a.time, dim::time, "--time");
  std::optional<Scene> scene;
  std::optional<DebrisMeter> meter;
  std::optional<DebrisResult> chosen;
  double best = 1e300;
  std::size_t frames = 0;
  StreamVisitor v;
  v.scene = [&](const std::string& t) { scene = scene_of(t, path); };
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
  const DebrisResult& r = *chosen;
  std::optional<double> ef, ew;
  if (!a.expect_front.empty()) ef = quantity(a.expect_front, dim::length, "--expect-front");
  if (!a.expect_width.empty()) ew = quantity(a.expect_width, dim::length, "--expect-width");
  if (a.json) {
    std::printf(
        "{\"time\": %s, \"axis\": \"%c\", \"direction\": %d, \"plane\": %s, \"cloud_particles\": "
        "%zu, "
        "\"particles\": %zu, \"percentile\": %s, \"front\": %s, \"width\": %s, "
        "\"front_max\": %s, \"front_p99\": %s, \"front_p99_5\": %s, \"front_p99_9\": %s, "
        "\"width_max\": %s, \"width_p99\": %s, \"width_p99_5\": %s, \"width_p99_9\": %s",
        json_number(r.time).c_str(), "xyz"[r.axis], r.direction, json_number(r.plane).c_str(),
        r.cloud, r.total, json_number(r.percentile).c_str(), json_number(r.front).c_str(),
        json_number(r.width).c_str(), json_number(r.front_max).c_str(),
        json_number(r.front_p99).c_str(), json_number(r.front_p995).c_str(),
        json_number(r.front_p999).c_str(), json_number(r.width_max).c_str(),
        json_number(r.width_p99).c_str(), json_number(r.width_p995).c_str(),
        json_number(r.width_p999).c_str());
    std::printf(
        ", \"link\": %s, \"min_fragment\": %zu, \"fragments\": %zu, \"single_particle_fragments\": "
        "%zu, "
        "\"largest_fragment\": %zu, \"counted_particles\": %zu, \"percentiles_of\": \"%s\"",
        json_number(r.link).c_str(), r.min_fragment, r.fragments, r.singles, r.largest, r.counted,
        r.by_mass ? "mass" : "particles");
    if (ef)
      std::printf(", \"expected_front\": %s, \"error_front\": %s", json_number(*ef).c_str(),
                  json_number(r.front / *ef - 1).c_str());
    if (ew)
      std::printf(", \"expected_width\": %s, \"error_width\": %s", json_number(*ew).c_str(),
                  json_number(r.width / *ew - 1).c_str());
    std::printf("}\n");
  } else {
    std::printf(
        "Debris cloud at t = %.4g us: %zu of %zu particles behind the plane %c = %.3f mm "
        "(the target's rear face), impact along %s%c\n",
        r.time * 1e6, r.cloud, r.total, "xyz"[r.axis], r.plane * 1e3, r.direction > 0 ? "+" : "-",
        "xyz"[r.axis]);
    std::printf(
        "  fragments (particles closer than %.3g mm linked): %zu, %zu of them single particles, "
        "the "
        "largest %zu particles\n",
        r.link * 1e3, r.fragments, r.singles, r.largest);
    if (r.min_fragment > 1)
      std::printf("  counted: the %zu particles of fragments of at least %zu particles\n",
                  r.counted, r.min_fragment);
    std::printf("  %-8s %10s %10s %10s %10s\n", "mm", "max", "p99", "p99.5", "p99.9");
    std::printf("  %-8s %10.1f %10.1f %10.1f %10.1f\n", "front", r.front_max * 1e3,
                r.front_p99 * 1e3, r.front_p995 * 1e3, r.front_p999 * 1e3);
    std::printf("  %-8s %10.1f %10.1f %10.1f %10.1f\n", "width", r.width_max * 1e3,
                r.width_p99 * 1e3, r.width_p995 * 1e3, r.width_p999 * 1e3);
    std::printf("  front = %.1f mm", r.front * 1e3);
    if (ef) std::printf(" (expected %.1f mm, %+.1f%%)", *ef * 1e3, 100 * (r.front / *ef - 1));
    std::printf(", width = %.1f mm", r.width * 1e3);
    if (ew) std::printf(" (expected %.1f mm, %+.1f%%)", *ew * 1e3, 100 * (r.width / *ew - 1));
    std::printf("   [%g-th percentile of the cloud's %s]\n", r.percentile,
                r.by_mass ? "mass" : "particles");
  }
  std::fflush(stdout);
  return conclude(path, s, frames);
}

// particles -------------------------------------------------------------------------------
/// One value of element i, component k of a column, as a double.
double column_value(const Column& c, std::size_t i, int k) {
  const std::size_t at = i * std::size_t(c.info().components) + std::size_t(k);
  const std::byte* d = c.data();
  switch (c.info().type) {
    case ScalarType::F64:
      return reinterpret_cast<const double*>(d)[at];
    case ScalarType::F32:
      return reinterpret_cast<const float*>(d)[at];
    case ScalarType::U8:
      return double(reinterpret_cast<const std::uint8_t*>(d)[at]);
    case ScalarType::U32:
      return double(reinterpret_cast<const std::uint32_t*>(d)[at]);
    case ScalarType::I32:
      return double(reinterpret_cast<const std::int32_t*>(d)[at]);
    case ScalarType::U64:
      return double(reinterpret_cast<const std::uint64_t*>(d)[at]);
  }
  return NAN;
}

/// The particles of one frame as CSV: a column per component (x_0, x_1, sigma_0 ... sigma_5).
int cmd_particles(const std::string& path, const std::string& out, const std::string& frame,
                  const std::vector<std::string>& cols) {
  long want = -1;
  if (frame != "last") {
    char* end = nullptr;
    want = std::strtol(frame.c_str(), &end, 10);
    if (!end || *end || want < 0)
      throw InputError("--frame", "expected a frame index or 'last', got '" + frame + "'");
  }
  std::optional<Frame> chosen;
  long index = 0;
  StreamVisitor v;
  v.frame = [&](Frame&& f) {
    if (want < 0 || index == want) chosen = std::move(f);
    ++index;
  };
  const StreamSummary s = read_stream(path, v);
  if (!chosen) {
    std::fprintf(stderr, "mpm-post: error: %s has no frame %s (it holds %ld)\n",
                 input_name(path).c_str(), frame.c_str(), index);
    return kExitBadInput;
  }
  std::vector<const Column*> picked;
  if (cols.empty()) {
    for (const auto& c : chosen->columns.columns()) picked.push_back(&c);
  } else {
    for (const auto& name : cols) {
      const Column* c = chosen->columns.find(name);
      if (!c) {
        std::string known;
        for (const auto& k : chosen->columns.columns())
          known += (known.empty() ? "" : ", ") + k.info().name;
        throw InputError("--columns",
                         "unknown particle column '" + name + "' (known: " + known + ")");
      }
      picked.push_back(c);
    }
  }
  std::FILE* f = out == "-" ? stdout : std::fopen(out.c_str(), "w");
  if (!f) throw IoError("cannot write '" + out + "': " + std::strerror(errno));
  std::fprintf(f, "# t = %.10g s, step %lld\n", chosen->time, (long long)chosen->step);
  bool first = true;
  for (const Column* c : picked)
    for (int k = 0; k < c->info().components; ++k) {
      std::fprintf(f, "%s%s", first ? "" : ",", c->info().name.c_str());
      if (c->info().components > 1) std::fprintf(f, "_%d", k);
      first = false;
    }
  std::fprintf(f, "\n");
  for (std::size_t i = 0; i < chosen->columns.size(); ++i) {
    first = true;
    for (const Column* c : picked)
      for (int k = 0; k < c->info().components; ++k) {
        std::fprintf(f, "%s%.10g", first ? "" : ",", column_value(*c, i, k));
        first = false;
      }
    std::fprintf(f, "\n");
  }
  if (f != stdout) {
    if (std::fclose(f) != 0) throw IoError("cannot write '" + out + "': " + std::strerror(errno));
  } else {
    std::fflush(stdout);
  }
  return conclude(path, s, std::size_t(index));
}

// profile ---------------------------------------------------------------------------------
struct ProfileArgs {
  std::string output = "-", component = "0", along = "x", from, to, radius, body;
  std::vector<std::string> times;
  std::vector<long> frames;
  ProfileOptions opt;
  bool json = false, grid = false;
};

Vec3 point(const std::string& text, const std::string& option) {
  std::vector<Quantity> qs;
  try {
    qs = parse_vector(text);
  } catch (const std::invalid_argument& e) {
    throw InputError(option, std::string(e.what()) + " in '" + text + "'");
  }
  if (qs.size() < 2 || qs.size() > 3)
    throw InputError(option, "expected 2 or 3 components, e.g. \"0 0 0 mm\", got '" + text + "'");
  Vec3 x = Vec3::Zero();
  for (std::size_t a = 0; a < qs.size(); ++a) {
    if (!(qs[a].dim == dim::length) && !(qs[a].dim == dim::none))
      throw InputError(option, "expected lengths, got '" + text + "'");
    x[a] = qs[a].value;
  }
  return x;
}

int cmd_profile(const std::string& path, ProfileArgs& a) {
  ProfileOptions& o = a.opt;
  o.component = component_index(a.component);
  if (a.along != "x" && a.along != "y" && a.along != "z")
    throw InputError("--along", "expected x, y or z, got '" + a.along + "'");
  o.axis = a.along[0] - 'x';
  if (a.from.empty() != a.to.empty())
    throw InputError(a.from.empty() ? "--from" : "--to", "give both --from and --to");
  if (!a.from.empty()) o.from = point(a.from, "--from"), o.to = point(a.to, "--to");
  if (!a.radius.empty()) o.radius = quantity(a.radius, dim::length, "--radius");
  std::vector<double> want_t;
  for (const auto& t : a.times) want_t.push_back(quantity(t, dim::time, "--time"));
  // Per request, the profile of the nearest frame (by time) or of the frame of that index;
  // default the last frame. Frames are profiled as they stream by (once each, when they are
  // nearer than any before), so memory stays bounded on pipes.
  std::vector<std::shared_ptr<Profile>> by_time(want_t.size()), by_index(a.frames.size());
  std::vector<double> best(want_t.size(), 1e300);
  std::shared_ptr<Profile> last;
  std::string scene_text;
  long index = 0;
  StreamVisitor v;
  v.scene = [&](const std::string& t) {
    scene_text = t;
    if (!a.body.empty() || a.grid) {
      const Scene sc = scene_of(scene_text, path);
      if (!a.body.empty()) {
        o.body = sc.body_index(a.body);
        if (o.body < 0) throw InputError("--body", "no body named '" + a.body + "' in the scene");
      }
      if (a.grid) {
        if (!sc.grid.levels.empty())
          throw InputError(
              "--grid",
              "the run's grid is graded (grid.levels): profiles on the grid need a uniform one");
        if (!sc.grid.domain_given)
          throw InputError("--grid",
                           "the stream's scene has no grid.domain (written by an older mpm-prep?)");
        o.on_grid = true;
        o.cell = sc.grid.cell_size;
        o.origin = sc.grid.domain_min;
      }
    }
  };
  v.frame = [&](Frame&& f) {
    if (a.grid && !o.on_grid)
      throw InputError("--grid", "the stream holds no scene before its frames");
    const long k = index++;
    const int dim = f.columns.at("x").info().components;
    std::shared_ptr<Profile> p;
    auto get = [&]() {
      if (!p) p = std::make_shared<Profile>(make_profile(f, dim, o));
      return p;
    };
    for (std::size_t r = 0; r < want_t.size(); ++r)
      if (std::abs(f.time - want_t[r]) < best[r])
        best[r] = std::abs(f.time - want_t[r]), by_time[r] = get();
    for (std::size_t r = 0; r < a.frames.size(); ++r)
      if (a.frames[r] == k) by_index[r] = get();
    if (want_t.empty() && a.frames.empty()) last = get();
  };
  const StreamSummary s = read_stream(path, v);
  std::vector<Profile> profiles;
  for (auto& p : by_time)
    if (p) profiles.push_back(*p);
  for (std::size_t r = 0; r < by_index.size(); ++r) {
    if (!by_index[r]) {
      std::fprintf(stderr, "mpm-post: error: %s has no frame %ld (it holds %ld)\n",
                   input_name(path).c_str(), a.frames[r], index);
      return kExitBadInput;
    }
    profiles.push_back(*by_index[r]);
  }
  if (last) profiles.push_back(*last);
  if (profiles.empty()) {
    std::fprintf(stderr, "mpm-post: error: %s holds no frame to profile\n",
                 input_name(path).c_str());
    return kExitBadInput;
  }
  std::FILE* out = a.output == "-" ? stdout : std::fopen(a.output.c_str(), "w");
  if (!out) throw IoError("cannot write '" + a.output + "': " + std::strerror(errno));
  const bool bins = o.bins > 0;
  if (a.json) {
    const Profile& p0 = profiles.front();
    std::fprintf(out,
                 "{\"field\": %s, \"component\": %d, \"unit\": %s, \"from\": [%s, %s, %s], \"to\": "
                 "[%s, %s, %s], \"profiles\": [",
                 json_string(o.field).c_str(), o.component, json_string(p0.unit).c_str(),
                 json_number(p0.from[0]).c_str(), json_number(p0.from[1]).c_str(),
                 json_number(p0.from[2]).c_str(), json_number(p0.to[0]).c_str(),
                 json_number(p0.to[1]).c_str(), json_number(p0.to[2]).c_str());
    for (std::size_t k = 0; k < profiles.size(); ++k) {
      const Profile& p = profiles[k];
      auto array = [&](const char* name, const std::vector<double>& x) {
        std::fprintf(out, ", \"%s\": [", name);
        for (std::size_t i = 0; i < x.size(); ++i)
          std::fprintf(out, "%s%s", i ? ", " : "", json_number(x[i]).c_str());
        std::fprintf(out, "]");
      };
      std::fprintf(out, "%s{\"time\": %s", k ? ", " : "", json_number(p.time).c_str());
      array("s", p.s);
      array("value", p.value);
      array("weight", p.weight);
      if (bins) {
        array("min", p.min);
        array("max", p.max);
        std::vector<double> c(p.count.begin(), p.count.end());
        array("count", c);
      }
      std::fprintf(out, "}");
    }
    std::fprintf(out, "]}\n");
  } else {
    std::fprintf(out, bins ? "time,s,value,min,max,count,weight\n" : "time,s,value,weight\n");
    for (const Profile& p : profiles)
      for (std::size_t i = 0; i < p.s.size(); ++i) {
        if (bins)
          std::fprintf(out, "%.10g,%.10g,%.10g,%.10g,%.10g,%zu,%.10g\n", p.time, p.s[i], p.value[i],
                       p.min[i], p.max[i], p.count[i], p.weight[i]);
        else
          std::fprintf(out, "%.10g,%.10g,%.10g,%.10g\n", p.time, p.s[i], p.value[i], p.weight[i]);
      }
  }
  if (out != stdout) {
    if (std::fclose(out) != 0)
      throw IoError("cannot write '" + a.output + "': " + std::strerror(errno));
  } else {
    std::fflush(stdout);
  }
  return conclude(path, s, std::size_t(index));
}

// render ----------------------------------------------------------------------------------
struct RenderArgs {
  std::string output = "frame.png", frame = "last", time, size = "1200x900", range;
  bool half = false;
  RenderOptions opt;
};

int cmd_render(const std::string& path, RenderArgs& a) {
  RenderOptions& o = a.opt;
  if (std::sscanf(a.size.c_str(), "%dx%d", &o.width, &o.height) != 2 || o.width < 16 ||
      o.height < 16)
    throw InputError("--size", "expected WIDTHxHEIGHT in pixels, got '" + a.size + "'");
  if (!a.range.empty() && std::sscanf(a.range.c_str(), "%lf:%lf", &o.range_min, &o.range_max) == 2)
    o.range_given = true;
  else if (!a.range.empty())
    throw InputError("--range", "expected MIN:MAX in the field's SI unit, got '" + a.range + "'");
  long want = -1;
  if (a.frame != "last") {
    char* end = nullptr;
    want = std::strtol(a.frame.c_str(), &end, 10);
    if (!end || *end || want < 0)
      throw InputError("--frame", "expected a frame index or 'last', got '" + a.frame + "'");
  }
  std::optional<double> at;
  if (!a.time.empty()) at = quantity(a.time, dim::time, "--time");
  std::optional<Frame> chosen;
  std::optional<Scene> scene;
  long index = 0;
  double best = 1e300;
  StreamVisitor v;
  v.scene = [&](const std::string& t) { scene = scene_of(t, path); };
  v.frame = [&](Frame&& f) {
    const long k = index++;
    if (at) {
      const double d = std::abs(f.time - *at);
      if (d < best) best = d, chosen = std::move(f);
    } else if (want < 0 || k == want) {
      chosen = std::move(f);
    }
  };
  const StreamSummary s = read_stream(path, v);
  if (!chosen) {
    std::fprintf(stderr, "mpm-post: error: %s has no frame %s (it holds %ld)\n",
                 input_name(path).c_str(), a.frame.c_str(), index);
    return kExitBadInput;
  }
  const int dim = chosen->columns.at("x").info().components;
  o.axisymmetric = scene && scene->axisymmetric && dim == 2;
  o.mirror = o.axisymmetric && !a.half;  // the whole section through the axis
  render_png(*chosen, dim, o, a.output);
  // The time in us for impact runs, in s for slow ones (forming, the dimensionless V7 scenes).
  const bool slow = chosen->time >= 1e-2;
  std::fprintf(stderr, "mpm-post: wrote %s (frame at t = %.4g %s, %zu particles, coloured by %s)\n",
               a.output.c_str(), slow ? chosen->time : chosen->time * 1e6, slow ? "s" : "us",
               chosen->columns.size(), o.field.c_str());
  return conclude(path, s, std::size_t(index));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "mpm-post: read a result stream (from mpm-run) and report.\n"
      "INPUT is a stream file or - for stdin. --json on measurements prints JSON.\n"
      "Exit status: 0 done, 2 bad input or damaged stream (the frames before the\n"
      "damage are still used), 3 the run was unstable, 4 write failure.",
      "mpm-post"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("mpm-post ") + mpm::kVersion);
  std::string input = "-";

  auto* summary = app.add_subcommand("summary", "what a stream holds: frames, history, end status");
  bool summary_json = false;
  summary->add_option("input", input, "stream, - for stdin")->capture_default_str();
  summary->add_flag("--json", summary_json, "print JSON");

  auto* history =
      app.add_subcommand("history", "time histories as CSV (energies, momentum, wall forces)");
  std::string hist_out = "-";
  std::vector<std::string> hist_cols;
  history->add_option("input", input, "stream, - for stdin")->capture_default_str();
  history->add_option("-o,--output", hist_out, "CSV file, - for stdout")->capture_default_str();
  history->add_option("--columns", hist_cols, "columns to print (default all)")->delimiter(',');

  auto* particles = app.add_subcommand(
      "particles", "the particles of one frame as CSV (one column per component)");
  std::string part_out = "-", part_frame = "last";
  std::vector<std::string> part_cols;
  particles->add_option("input", input, "stream, - for stdin")->capture_default_str();
  particles->add_option("-o,--output", part_out, "CSV file, - for stdout")->capture_default_str();
  particles->add_option("--frame", part_frame, "frame index (0 = first) or 'last'")
      ->capture_default_str();
  particles->add_option("--columns", part_cols, "particle columns (default all), e.g. x,sigma")
      ->delimiter(',');

  auto* vtk = app.add_subcommand("vtk", "ParaView files: a .vtu per frame and a .pvd series");
  std::string vtk_dir = "vtk", vtk_name = "frame";
  int vtk_every = 1;
  vtk->add_option("input", input, "stream, - for stdin")->capture_default_str();
  vtk->add_option("-o,--output", vtk_dir, "directory")->capture_default_str();
  vtk->add_option("--name", vtk_name, "file name prefix")->capture_default_str();
  vtk->add_option("--every", vtk_every, "write every Nth frame (the final one always)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();

  auto* taylor = app.add_subcommand(
      "taylor", "final length L and foot diameter D (mean caliper width) of a bar against a wall");
  TaylorArgs ta;
  taylor->add_option("input", input, "stream, - for stdin")->capture_default_str();
  taylor->add_option("--body", ta.body, "body name (default: the first)");
  taylor->add_option("--axis", ta.axis, "bar axis x, y or z (default: its longest extent)");
  taylor->add_option(
      "--wall", ta.wall,
      "wall position along the axis, e.g. \"0 mm\" (default: the constrained domain face)");
  taylor->add_flag(
      "--surface", ta.surface,
      "measure the surface (centres + half a particle spacing) instead of particle centres");
  taylor->add_option("--expect-L", ta.expect_L,
                     "reference length, e.g. \"16.2 mm\", to print the difference");
  taylor->add_option("--expect-D", ta.expect_D, "reference diameter, e.g. \"13.5 mm\"");
  taylor->add_flag("--json", ta.json, "print JSON (SI units)");

  auto* debris =
      app.add_subcommand("debris", "front and width of a debris cloud behind a struck plate");
  DebrisArgs da;
  debris->add_option("input", input, "stream, - for stdin")->capture_default_str();
  debris->add_option("--time", da.time,
                     "the frame nearest this time, e.g. \"30.6 us\" (default: the last)");
  debris->add_option("--axis", da.axis,
                     "impact axis x, y or z (default: the projectile's velocity)");
  debris->add_option(
      "--plane", da.plane,
      "reference plane along the axis, e.g. \"6.36 mm\" (default: the target's rear face)");
  debris->add_option("--target", da.target, "target body (default: the first body at rest)");
  debris->add_option("--projectile", da.projectile, "projectile body (default: the fastest body)");
  debris
      ->add_option(
          "--percentile", da.percentile,
          "which particles count: the front and width reported are this percentile of the "
          "cloud's distances, by mass (stray particles beyond it are ignored; max and 99/99.5/99.9 "
          "are always printed; axisymmetric: the axis is y, each ring weighs its mass)")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  debris
      ->add_option("--min-fragment", da.min_fragment,
                   "which particles count: only those of fragments of at least this many particles "
                   "(particles closer than --link are one fragment); 1: all")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  debris->add_option("--link", da.link,
                     "linking length of fragments, e.g. \"1 mm\" (default: the grid's cell size)");
  debris->add_option("--expect-front", da.expect_front, "reference front, e.g. \"200 mm\"");
  debris->add_option("--expect-width", da.expect_width, "reference width, e.g. \"145 mm\"");
  debris->add_flag("--json", da.json, "print JSON (SI units)");
  auto* profile =
      app.add_subcommand("profile", "a field along a line (stress waves, shocks), CSV or JSON");
  ProfileArgs pa;
  profile->add_option("input", input, "stream, - for stdin")->capture_default_str();
  profile->add_option("-o,--output", pa.output, "CSV (or JSON) file, - for stdout")
      ->capture_default_str();
  profile
      ->add_option("--field", pa.opt.field,
                   "a column (sigma, v, eps_p, ...) or pressure, von_mises, speed")
      ->capture_default_str();
  profile
      ->add_option("--component", pa.component,
                   "xx, yy, zz, yz, xz, xy (tensors), x, y, z (vectors), an index, or magnitude")
      ->capture_default_str();
  profile
      ->add_option("--along", pa.along,
                   "the line's direction when --from/--to are not given: x, y or z, over the "
                   "particles' extent through their centroid")
      ->capture_default_str();
  profile->add_option("--from", pa.from, "start of the line, e.g. \"0 0 0 mm\"");
  profile->add_option("--to", pa.to, "end of the line");
  profile->add_option(
      "--radius", pa.radius,
      "leave out particles farther than this from the line, e.g. \"1 mm\" (default: none)");
  profile->add_option("--body", pa.body, "only this body's particles");
  profile->add_option(
      "--bins", pa.opt.bins,
      "average in this many equal bins along the line (default: one row per particle)");
  profile->add_flag("--grid", pa.grid,
                    "on the grid: project the field onto the run's grid nodes (linear shape "
                    "functions, mass-weighted) and profile the nodes near the line");
  profile->add_option("--time", pa.times, "the frame nearest this time, e.g. 9us (repeatable)");
  profile->add_option("--frame", pa.frames,
                      "frame index, 0 = first (repeatable); default: the last frame");
  profile->add_flag("--json", pa.json, "print JSON (SI units)");

  auto* render =
      app.add_subcommand("render", "PNG picture of a frame, off-screen (works without a display)");
  RenderArgs ra;
  render->add_option("input", input, "stream, - for stdin")->capture_default_str();
  render->add_option("-o,--output", ra.output, "PNG file")->capture_default_str();
  render->add_option("--frame", ra.frame, "frame index (0 = first) or 'last'")
      ->capture_default_str();
  render->add_option("--time", ra.time, "the frame nearest this time, e.g. \"30.6 us\"");
  render
      ->add_option("--field", ra.opt.field,
                   "colour by: a column (eps_p, rho, e, ...) or pressure, von_mises, speed")
      ->capture_default_str();
  render->add_option("--component", ra.opt.component,
                     "component of a vector field (-1: magnitude)");
  render->add_option("--view", ra.opt.view, "side, front, top or iso")
      ->check(CLI::IsMember({"side", "front", "top", "iso"}))
      ->capture_default_str();
  render->add_option("--clip", ra.opt.clip,
                     "keep one side of a plane through the centroid, e.g. \"y>0\"");
  render->add_option("--size", ra.size, "WIDTHxHEIGHT in pixels")->capture_default_str();
  render->add_option("--range", ra.range, "colour range MIN:MAX (SI units)");
  render->add_option("--title", ra.opt.title, "title text");
  render->add_option("--radius", ra.opt.point_radius,
                     "particle radius in m (default from mass and density)");
  render->add_flag(
      "--half", ra.half,
      "axisymmetric frames: draw the half plane r >= 0 only (default: the whole section, mirrored "
      "about the axis)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : mpm::kExitBadInput;
  }
  return mpm::guarded_main("mpm-post", [&]() -> int {
    mpm::ignore_sigpipe();
    // No subcommand writes over the stream it reads.
    if (*history) mpm::check_output_file(hist_out, {input});
    if (*particles) mpm::check_output_file(part_out, {input});
    if (*profile) mpm::check_output_file(pa.output, {input});
    if (*render) mpm::check_output_file(ra.output, {input});
    if (*summary) return cmd_summary(input, summary_json);
    if (*history) return cmd_history(input, hist_out, hist_cols);
    if (*particles) return cmd_particles(input, part_out, part_frame, part_cols);
    if (*vtk) return cmd_vtk(input, vtk_dir, vtk_name, vtk_every);
    if (*taylor) return cmd_taylor(input, ta);
    if (*debris) return cmd_debris(input, da);
    if (*profile) return cmd_profile(input, pa);
    if (*render) {
      mpm::ensure_display(argc, argv);  // before reading: a re-run under xvfb reads stdin again
      return cmd_render(input, ra);
    }
    return mpm::kExitBadInput;
  });
}
