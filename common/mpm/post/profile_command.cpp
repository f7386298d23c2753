// mpm-post profile: profiles of a field along a line of the frames asked for, CSV or JSON.
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

#include "mpm/core/error.hpp"
#include "mpm/post/arguments.hpp"
#include "mpm/post/command_io.hpp"
#include "mpm/post/commands.hpp"
#include "mpm/post/json.hpp"

namespace mpm {

namespace {

/// The profile options of the command-line values (all but the body and the grid, which need
/// the scene).
ProfileOptions profile_options(const ProfileArgs& a) {
  ProfileOptions o = a.profile;
  o.component = component_index(a.component);
  o.axis = option_axis(a.along, "--along");
  if (a.from.empty() != a.to.empty())
    throw InputError(a.from.empty() ? "--from" : "--to", "give both --from and --to");
  if (!a.from.empty()) o.from = option_point(a.from, "--from"), o.to = option_point(a.to, "--to");
  if (!a.radius.empty()) o.radius = option_quantity(a.radius, dim::length, "--radius");
  if (a.weight != "volume" && a.weight != "mass")
    throw InputError("--weight", "expected volume or mass, got '" + a.weight + "'");
  o.weight = a.weight == "mass" ? ProfileWeight::Mass : ProfileWeight::Volume;
  return o;
}

/// The body (--body) and the uniform grid (--grid) of the stream's scene in the options.
void apply_scene(const std::string& scene_text, const ProfileArgs& a, ProfileOptions& o) {
  if (a.body.empty() && !a.grid) return;
  const Scene sc = scene_of(scene_text, a.input);
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

/// The profiles asked for, as frames stream by: per requested time the nearest frame, per
/// requested index that frame, else the last frame. Each frame is profiled once, and only
/// when it is nearer than any before, so memory stays bounded on pipes.
class ProfilePicker {
 public:
  ProfilePicker(const std::vector<double>& times, const std::vector<long>& frames)
      : times_(times),
        frames_(frames),
        by_time_(times.size()),
        by_index_(frames.size()),
        best_(times.size(), 1e300) {}

  /// Profiles frame `k` if a request wants it.
  void offer(const Frame& f, long k, const ProfileOptions& o) {
    const int dim = f.columns.at("x").info().components;
    std::shared_ptr<Profile> p;
    auto get = [&]() {
      if (!p) p = std::make_shared<Profile>(make_profile(f, dim, o));
      return p;
    };
    for (std::size_t r = 0; r < times_.size(); ++r)
      if (std::abs(f.time - times_[r]) < best_[r])
        best_[r] = std::abs(f.time - times_[r]), by_time_[r] = get();
    for (std::size_t r = 0; r < frames_.size(); ++r)
      if (frames_[r] == k) by_index_[r] = get();
    if (times_.empty() && frames_.empty()) last_ = get();
  }

  /// The profiles in request order (times, then indices, then the last frame); returns the
  /// index of a requested frame the stream did not hold, if any.
  std::optional<long> collect(std::vector<Profile>& profiles) const {
    for (auto& p : by_time_)
      if (p) profiles.push_back(*p);
    for (std::size_t r = 0; r < by_index_.size(); ++r) {
      if (!by_index_[r]) return frames_[r];
      profiles.push_back(*by_index_[r]);
    }
    if (last_) profiles.push_back(*last_);
    return std::nullopt;
  }

 private:
  std::vector<double> times_;
  std::vector<long> frames_;
  std::vector<std::shared_ptr<Profile>> by_time_, by_index_;
  std::vector<double> best_;
  std::shared_ptr<Profile> last_;
};

void write_profiles_json(std::FILE* out, const std::vector<Profile>& profiles,
                         const ProfileOptions& o) {
  const Profile& p0 = profiles.front();
  JsonWriter j;
  j.begin_object().key("field").string(o.field).key("component").integer(o.component);
  j.key("unit").string(p0.unit);
  j.key("weighted_by").string(o.on_grid || o.weight == ProfileWeight::Mass ? "mass" : "volume");
  j.key("from").numbers({p0.from[0], p0.from[1], p0.from[2]});
  j.key("to").numbers({p0.to[0], p0.to[1], p0.to[2]});
  j.key("profiles").begin_array();
  for (const Profile& p : profiles) {
    j.begin_object().key("time").number(p.time);
    j.key("s").numbers(p.s).key("value").numbers(p.value).key("weight").numbers(p.weight);
    if (o.bins > 0) {
      j.key("min").numbers(p.min).key("max").numbers(p.max);
      j.key("count").numbers(std::vector<double>(p.count.begin(), p.count.end()));
    }
    j.end_object();
  }
  j.end_array().end_object();
  std::fprintf(out, "%s\n", j.text().c_str());
}

void write_profiles_csv(std::FILE* out, const std::vector<Profile>& profiles,
                        const ProfileOptions& o) {
  const bool bins = o.bins > 0;
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

}  // namespace

int post_profile(const ProfileArgs& a) {
  const std::string& path = a.input;
  ProfileOptions o = profile_options(a);
  std::vector<double> want_t;
  for (const auto& t : a.times) want_t.push_back(option_quantity(t, dim::time, "--time"));
  ProfilePicker picker(want_t, a.frames);
  long index = 0;
  StreamVisitor v;
  v.scene = [&](const std::string& t) { apply_scene(t, a, o); };
  v.frame = [&](Frame&& f) {
    if (a.grid && !o.on_grid)
      throw InputError("--grid", "the stream holds no scene before its frames");
    picker.offer(f, index++, o);
  };
  const StreamSummary s = read_stream(path, v);
  std::vector<Profile> profiles;
  if (const std::optional<long> missing = picker.collect(profiles)) {
    std::fprintf(stderr, "mpm-post: error: %s has no frame %ld (it holds %ld)\n",
                 input_name(path).c_str(), *missing, index);
    return kExitBadInput;
  }
  if (profiles.empty()) {
    std::fprintf(stderr, "mpm-post: error: %s holds no frame to profile\n",
                 input_name(path).c_str());
    return kExitBadInput;
  }
  std::FILE* out = open_output(a.output);
  if (a.json)
    write_profiles_json(out, profiles, o);
  else
    write_profiles_csv(out, profiles, o);
  close_output(out, a.output);
  return conclude(path, s, std::size_t(index));
}

}  // namespace mpm
