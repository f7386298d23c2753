// mpm-post summary, history and particles: what a result stream holds, as text, JSON or CSV.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <optional>

#include "mpm/core/error.hpp"
#include "mpm/post/arguments.hpp"
#include "mpm/post/column_value.hpp"
#include "mpm/post/command_io.hpp"
#include "mpm/post/commands.hpp"
#include "mpm/post/json.hpp"

namespace mpm {

namespace {

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
};

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
  j.key("damage").string(s.damage).end_object();
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

/// The CSV of particles: a comment with the time and step, a header, a row per particle.
void write_particles_csv(std::FILE* f, const std::string& path, const Frame& frame,
                         const std::vector<const Column*>& picked) {
  std::fprintf(f, "# t = %.10g s, step %lld\n", frame.time, (long long)frame.step);
  bool first = true;
  for (const Column* c : picked)
    for (int k = 0; k < c->info().components; ++k) {
      std::fprintf(f, "%s%s", first ? "" : ",", c->info().name.c_str());
      if (c->info().components > 1) std::fprintf(f, "_%d", k);
      first = false;
    }
  std::fprintf(f, "\n");
  for (std::size_t i = 0; i < frame.columns.size(); ++i) {
    first = true;
    for (const Column* c : picked)
      for (int k = 0; k < c->info().components; ++k) {
        std::fprintf(f, "%s%.10g", first ? "" : ",", column_value(*c, i, k));
        first = false;
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
  v.frame = [&](Frame&& f) { c.frames.push_back({f.step, f.time, f.columns.size(), f.flags}); };
  v.history = [&](HistoryBlock&& h) {
    c.hist_rows += h.rows();
    if (c.hist_names.empty()) c.hist_names = h.names;
  };
  const StreamSummary s = read_stream(path, v);
  if (!scene_text.empty()) {
    const Scene sc = scene_of(scene_text, path);
    c.title = sc.title;
    c.dim = sc.dimension;
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
      for (std::size_t k = 0; k < pick.size(); ++k)
        std::fprintf(f, "%s%s", k ? "," : "", names[pick[k]].c_str());
      std::fprintf(f, "\n");
    }
    const std::size_t nc = h.names.size();
    for (std::size_t r = 0; r < h.rows(); ++r) {
      for (std::size_t k = 0; k < pick.size(); ++k)
        std::fprintf(f, "%s%.10g", k ? "," : "", h.values[r * nc + pick[k]]);
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
  StreamVisitor v;
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
  write_particles_csv(f, a.output, *chosen, picked);
  close_output(f, a.output);
  return conclude(a.input, s, std::size_t(index));
}

}  // namespace mpm
