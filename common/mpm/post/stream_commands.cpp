// mpm-post summary, history and particles: what a result stream holds, as text, JSON or CSV.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <optional>

#include "mpm/core/error.hpp"
#include "mpm/core/types.hpp"
#include "mpm/post/arguments.hpp"
#include "mpm/post/column_value.hpp"
#include "mpm/post/command_io.hpp"
#include "mpm/post/commands.hpp"
#include "mpm/post/json.hpp"
#include "mpm/scene/particles.hpp"
#include "mpm/scene/rebar_elements.hpp"

namespace mpm {

namespace {

/// Mass (kg) and momentum (kg m/s) of a set of particles: a frame, or escaped particles.
struct Sums {
  std::size_t n = 0;
  double mass = 0;
  Vec3 momentum = Vec3::Zero();
  /// Adds the particles of `f` (its columns m and v; false when it has not both).
  bool add(const Frame& f) {
    const Column *m = f.columns.find("m"), *v = f.columns.find("v");
    if (!m || !v) return false;
    const int d = v->info().components;
    n += f.columns.size();
    for (std::size_t i = 0; i < f.columns.size(); ++i) {
      const double m_p = column_value(*m, i, 0);
      mass += m_p;
      for (int a = 0; a < d && a < 3; ++a) momentum[a] += m_p * column_value(*v, i, a);
    }
    return true;
  }
};

/// The mass and momentum budget of a run: the first frame against the last one plus the
/// particles that left the domain before it (ESCP records).
struct Budget {
  bool valid = true;  ///< every frame and ESCP record had m and v
  bool any = false;   ///< a frame was seen
  Sums initial, domain, escaped_now, escaped;
  double t0 = 0, t = 0;
  void frame(const Frame& f) {
    Sums s;
    valid = s.add(f) && valid;
    if (!any) initial = s, t0 = f.time;
    any = true;
    domain = s;
    t = f.time;
    escaped = escaped_now;
  }
  void escapes(const Frame& f) { valid = escaped_now.add(f) && valid; }
};

/// What summary reports of a stream.
struct StreamContents {
  struct FrameEntry {
    std::int64_t step;
    double time;
    std::size_t n;
    std::uint32_t flags;
  };
  std::string title;
  int dim = 0;
  std::vector<FrameEntry> frames;
  std::size_t hist_rows = 0;
  std::vector<std::string> hist_names;
  Budget budget;
  double factor = 1;      ///< extensive values per model unit to whole bodies
  bool external = false;  ///< faces, loads, gravity or rigid bodies change the momentum
  struct RebarEntry {
    double time;
    std::size_t elements, eroded;
  };
  std::vector<RebarEntry> rebar;  ///< the REBR records: elements and those eroded
};

/// The rebar's elements and how many of them were eroded, per REBR record.
void print_rebar_text(const StreamContents& c) {
  if (c.rebar.empty()) return;
  const auto& last = c.rebar.back();
  std::printf("rebar: %zu elements, %zu eroded at t = %.4f us (%zu records)\n", last.elements,
              last.eroded, last.time * 1e6, c.rebar.size());
}

void print_budget_json(JsonWriter& j, const StreamContents& c) {
  const Budget& b = c.budget;
  auto sums = [&](const char* name, const Sums& s) {
    j.key(name).begin_object().key("particles").integer(s.n).key("mass").number(c.factor * s.mass);
    j.key("momentum")
        .numbers({c.factor * s.momentum[0], c.factor * s.momentum[1], c.factor * s.momentum[2]});
    j.end_object();
  };
  j.key("budget").begin_object().key("time").number(b.t);
  sums("initial", b.initial);
  sums("domain", b.domain);
  sums("escaped", b.escaped);
  const Vec3 dp = c.factor * (b.domain.momentum + b.escaped.momentum - b.initial.momentum);
  j.key("mass_error").number(c.factor * (b.domain.mass + b.escaped.mass - b.initial.mass));
  j.key("momentum_error").numbers({dp[0], dp[1], dp[2]});
  j.key("external_forces").boolean(c.external).end_object();
}

void print_budget_text(const StreamContents& c) {
  const Budget& b = c.budget;
  if (!b.any) return;
  if (!b.valid) {
    std::printf("budget: the frames lack the m or v column (output.fields)\n");
    return;
  }
  const double k = c.factor;
  std::printf("budget (mass and momentum: in the domain + escaped = initial):\n");
  std::printf("  %-30s %10s %14s %14s %14s %14s\n", "", "particles", "mass kg", "p_x kg m/s",
              "p_y kg m/s", "p_z kg m/s");
  auto row = [&](const std::string& what, const Sums& s) {
    std::printf("  %-30s %10zu %14.8g %14.8g %14.8g %14.8g\n", what.c_str(), s.n, k * s.mass,
                k * s.momentum[0], k * s.momentum[1], k * s.momentum[2]);
  };
  char at[64];
  std::snprintf(at, sizeof at, "initial (t = %.4g us)", b.t0 * 1e6);
  row(at, b.initial);
  std::snprintf(at, sizeof at, "in the domain (t = %.4g us)", b.t * 1e6);
  row(at, b.domain);
  row("escaped by then", b.escaped);
  const double dm = b.domain.mass + b.escaped.mass - b.initial.mass;
  const Vec3 dp = b.domain.momentum + b.escaped.momentum - b.initial.momentum;
  const double p_scale = std::max(b.initial.momentum.norm(), 1e-300);
  std::printf("  %-30s %10lld %14.3g %14.3g %14.3g %14.3g\n", "domain + escaped - initial",
              (long long)(b.domain.n + b.escaped.n) - (long long)b.initial.n, k * dm, k * dp[0],
              k * dp[1], k * dp[2]);
  std::printf("  relative: mass %.3g, momentum %.3g of |initial momentum|%s\n",
              dm / std::max(b.initial.mass, 1e-300), dp.norm() / p_scale,
              c.external ? " (boundary faces, loads, gravity or rigid bodies act on the material: "
                           "their impulse is in the momentum difference)"
                         : "");
}

/// Whether anything but the particles themselves changes their momentum.
bool external_forces(const Scene& sc) {
  for (int f = 0; f < 2 * sc.dimension; ++f)
    if (sc.boundary.face[f] != BoundaryType::Free) return true;
  for (const auto& b : sc.bodies)
    if (b.rigid) return true;
  return !sc.loads.empty() || sc.solver.gravity[0] != 0 || sc.solver.gravity[1] != 0 ||
         sc.solver.gravity[2] != 0;
}

void print_summary_json(const std::string& path, const StreamContents& c, const StreamSummary& s) {
  JsonWriter j;
  j.begin_object();
  j.key("input").string(input_name(path)).key("title").string(c.title);
  j.key("dimension").integer(c.dim).key("frames").begin_array();
  for (const auto& f : c.frames) {
    j.begin_object().key("step").integer(f.step).key("time").number(f.time);
    j.key("particles").integer(f.n).end_object();
  }
  j.end_array().key("history_rows").integer(c.hist_rows).key("ended").boolean(s.ended);
  j.key("status").integer(s.end_status).key("message").string(s.end_message);
  j.key("damage").string(s.damage);
  if (!c.rebar.empty())
    j.key("rebar_elements")
        .integer(c.rebar.back().elements)
        .key("rebar_eroded")
        .integer(c.rebar.back().eroded);
  if (c.budget.any && c.budget.valid) print_budget_json(j, c);
  j.end_object();
  std::printf("%s\n", j.text().c_str());
}

void print_summary_text(const std::string& path, const StreamContents& c, const StreamSummary& s) {
  std::printf("stream: %s\n", input_name(path).c_str());
  if (!c.title.empty()) std::printf("scene: %s (%dD)\n", c.title.c_str(), c.dim);
  std::printf("frames: %zu\n", c.frames.size());
  std::printf("  %8s %14s %12s\n", "step", "time (us)", "particles");
  for (const auto& f : c.frames)
    std::printf("  %8lld %14.4f %12zu%s\n", (long long)f.step, f.time * 1e6, f.n,
                (f.flags & kFrameModel)   ? "  (model)"
                : (f.flags & kFrameFinal) ? "  (final)"
                                          : "");
  std::printf("history: %zu rows", c.hist_rows);
  if (!c.hist_names.empty()) {
    std::printf(" of");
    for (auto& n : c.hist_names) std::printf(" %s", n.c_str());
  }
  std::printf("\nend: %s\n",
              s.ended ? ("status " + std::to_string(s.end_status) + ", " + s.end_message).c_str()
                      : "missing (the producer stopped early or is still running)");
  print_budget_text(c);
  print_rebar_text(c);
  if (!s.damage.empty()) std::printf("damage: %s\n", s.damage.c_str());
}

/// The indices of the history columns `wanted` in `names`; all of them when none is wanted.
std::vector<int> history_columns(const std::vector<std::string>& names,
                                 const std::vector<std::string>& wanted) {
  std::vector<int> pick;
  if (wanted.empty()) {
    for (std::size_t k = 0; k < names.size(); ++k) pick.push_back(int(k));
    return pick;
  }
  for (const auto& c : wanted) {
    auto it = std::find(names.begin(), names.end(), c);
    if (it == names.end()) {
      std::string known;
      for (auto& n : names) known += (known.empty() ? "" : ", ") + n;
      throw InputError("--columns", "unknown history column '" + c + "' (known: " + known + ")");
    }
    pick.push_back(int(it - names.begin()));
  }
  return pick;
}

/// The columns of a frame named in `wanted`; all of them when none is wanted.
std::vector<const Column*> particle_columns(const Frame& frame,
                                            const std::vector<std::string>& wanted) {
  std::vector<const Column*> picked;
  if (wanted.empty()) {
    for (const auto& c : frame.columns.columns()) picked.push_back(&c);
    return picked;
  }
  for (const auto& name : wanted) {
    const Column* c = frame.columns.find(name);
    if (!c) {
      std::string known;
      for (const auto& k : frame.columns.columns())
        known += (known.empty() ? "" : ", ") + k.info().name;
      throw InputError("--columns",
                       "unknown particle column '" + name + "' (known: " + known + ")");
    }
    picked.push_back(c);
  }
  return picked;
}

/// The CSV of particles: comments with the time and step and the columns' units, a header, a
/// row per particle. With `body_names` (from the stream's scene) and the body column picked, a
/// last column body_name names each particle's body.
void write_particles_csv(std::FILE* f, const std::string& path, const Frame& frame,
                         const std::vector<const Column*>& picked,
                         const std::vector<std::string>& body_names, int digits) {
  std::fprintf(f, "# t = %.10g s, step %lld\n", frame.time, (long long)frame.step);
  const Column* body = nullptr;
  for (const Column* c : picked)
    if (c->info().name == col::body && !body_names.empty()) body = c;
  std::string header, units;
  for (const Column* c : picked)
    for (int k = 0; k < c->info().components; ++k) {
      if (!header.empty()) header += ',', units += ',';
      header += c->info().name;
      if (c->info().components > 1) header += "_" + std::to_string(k);
      units += c->info().unit.empty() ? "-" : c->info().unit;
    }
  if (body) header += ",body_name", units += ",-";
  std::fprintf(f, "# units: %s\n%s\n", units.c_str(), header.c_str());
  for (std::size_t i = 0; i < frame.columns.size(); ++i) {
    bool first = true;
    for (const Column* c : picked)
      for (int k = 0; k < c->info().components; ++k) {
        std::fprintf(f, "%s%.*g", first ? "" : ",", digits, column_value(*c, i, k));
        first = false;
      }
    if (body) {
      const auto b = std::size_t(column_value(*body, i, 0));
      std::fprintf(f, ",%s", b < body_names.size() ? body_names[b].c_str() : "?");
    }
    std::fprintf(f, "\n");
    check_written(f, path);
  }
}

}  // namespace

int post_summary(const SummaryArgs& a) {
  const std::string& path = a.input;
  std::string scene_text;
  StreamContents c;
  StreamVisitor v;
  v.scene = [&](const std::string& t) { scene_text = t; };
  v.frame = [&](Frame&& f) {
    c.frames.push_back({f.step, f.time, f.columns.size(), f.flags});
    c.budget.frame(f);
  };
  v.escapes = [&](Frame&& f) { c.budget.escapes(f); };
  v.rebar = [&](Frame&& f) {
    const Column* e = f.columns.find(rebar_col::eroded);
    std::size_t eroded = 0;
    if (e && e->info().type == ScalarType::U8 && e->info().components == 1)
      for (std::size_t k = 0; k < f.columns.size(); ++k) eroded += e->as<std::uint8_t>()[k] != 0;
    c.rebar.push_back({f.time, f.columns.size(), eroded});
  };
  v.history = [&](HistoryBlock&& h) {
    c.hist_rows += h.rows();
    if (c.hist_names.empty()) c.hist_names = h.names;
  };
  const StreamSummary s = read_stream(path, v);
  if (!scene_text.empty()) {
    const Scene sc = scene_of(scene_text, path);
    c.title = sc.title;
    c.dim = sc.dimension;
    c.factor = sc.measure_factor();
    c.external = external_forces(sc);
  }
  if (a.json)
    print_summary_json(path, c, s);
  else
    print_summary_text(path, c, s);
  if (!s.damage.empty()) {
    std::fprintf(stderr, "mpm-post: error: %s\n", s.damage.c_str());
    return kExitBadInput;
  }
  return kExitOk;
}

int post_history(const HistoryArgs& a) {
  std::vector<std::string> names;
  std::vector<int> pick;
  std::FILE* f = open_output(a.output);
  std::size_t frames = 0;
  StreamVisitor v;
  v.want_frames = false;
  v.frame = [&](Frame&&) { ++frames; };
  v.history = [&](HistoryBlock&& h) {
    if (names.empty()) {
      names = h.names;
      pick = history_columns(names, a.columns);
      std::fprintf(f, "# units:");
      for (std::size_t k = 0; k < pick.size(); ++k)
        std::fprintf(f, "%s%s", k ? "," : " ", h.units[pick[k]].c_str());
      std::fprintf(f, "\n");
      for (std::size_t k = 0; k < pick.size(); ++k)
        std::fprintf(f, "%s%s", k ? "," : "", names[pick[k]].c_str());
      std::fprintf(f, "\n");
    }
    const std::size_t nc = h.names.size();
    for (std::size_t r = 0; r < h.rows(); ++r) {
      for (std::size_t k = 0; k < pick.size(); ++k)
        std::fprintf(f, "%s%.*g", k ? "," : "", a.digits, h.values[r * nc + pick[k]]);
      std::fprintf(f, "\n");
      check_written(f, a.output);
    }
  };
  const StreamSummary s = read_stream(a.input, v);
  // The close is not checked here (unlike particles and profile), as it never was.
  if (f != stdout)
    std::fclose(f);
  else
    std::fflush(stdout);
  return conclude(a.input, s, frames);
}

int post_particles(const ParticlesArgs& a) {
  const long want = option_frame(a.frame);
  std::optional<Frame> chosen;
  long index = 0;
  std::string scene_text;
  StreamVisitor v;
  v.scene = [&](const std::string& t) { scene_text = t; };
  v.frame = [&](Frame&& f) {
    if (want < 0 || index == want) chosen = std::move(f);
    ++index;
  };
  const StreamSummary s = read_stream(a.input, v);
  if (!chosen) {
    std::fprintf(stderr, "mpm-post: error: %s has no frame %s (it holds %ld)\n",
                 input_name(a.input).c_str(), a.frame.c_str(), index);
    return kExitBadInput;
  }
  const std::vector<const Column*> picked = particle_columns(*chosen, a.columns);
  std::FILE* f = open_output(a.output);
  std::vector<std::string> body_names;
  if (!scene_text.empty())
    for (const BodySpec& b : scene_of(scene_text, a.input).bodies) body_names.push_back(b.name);
  write_particles_csv(f, a.output, *chosen, picked, body_names, a.digits);
  close_output(f, a.output);
  return conclude(a.input, s, std::size_t(index));
}

int post_scene(const SceneArgs& a) {
  std::string scene_text;
  bool seen = false;
  std::size_t frames = 0;
  StreamVisitor v;
  v.want_frames = false;
  v.scene = [&](const std::string& t) {
    if (!seen) scene_text = t;
    seen = true;
  };
  v.frame = [&](Frame&&) { ++frames; };
  const StreamSummary s = read_stream(a.input, v);
  if (!seen) {
    std::fprintf(stderr, "mpm-post: error: %s holds no scene record\n",
                 input_name(a.input).c_str());
    return kExitBadInput;
  }
  std::FILE* f = open_output(a.output);
  std::fprintf(f, "%s", scene_text.c_str());
  if (!scene_text.empty() && scene_text.back() != '\n') std::fprintf(f, "\n");
  check_written(f, a.output);
  close_output(f, a.output);
  return conclude(a.input, s, frames);
}

}  // namespace mpm
