// mpm-post residual: a projectile's velocity through a target, its residual velocity, exit
// angle and mass lost, as text or JSON, and its history as CSV.
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>

#include "mpm/core/error.hpp"
#include "mpm/post/command_io.hpp"
#include "mpm/post/commands.hpp"
#include "mpm/post/json.hpp"
#include "mpm/post/residual.hpp"

namespace mpm {

namespace {

void sample_json(JsonWriter& j, const ResidualSample& s) {
  j.begin_object().key("time").number(s.time);
  j.key("velocity").numbers({s.v.x(), s.v.y(), s.v.z()});
  j.key("speed").number(s.v.norm()).key("along").number(s.v_along);
  j.key("angle_deg").number(s.angle).key("mass").number(s.mass);
  j.key("failed_mass").number(s.failed_mass).key("tail").number(s.tail);
  j.key("intact_particles").integer(s.intact).end_object();
}

void print_residual_json(const ResidualResult& r) {
  JsonWriter j;
  j.begin_object().key("body").string(r.body).key("targets").begin_array();
  for (const std::string& t : r.targets) j.string(t);
  j.end_array();
  const Vec3& d = r.direction;
  j.key("direction").numbers({d.x(), d.y(), d.z()});
  j.key("initial_speed").number(r.history.front().v_along);
  j.key("face_axis").string(std::string(1, "xyz"[r.axis])).key("face_sign").integer(r.sign);
  j.key("far_face").number(r.far_face).key("perforated").boolean(r.exit.has_value());
  j.key("residual_velocity").number(r.end().v.norm());
  j.key("exit_velocity").number(r.exit ? r.exit->v.norm() : NAN);
  j.key("exit_angle_deg").number(r.exit ? r.exit->angle : NAN);
  j.key("exit");
  if (r.exit)
    sample_json(j, *r.exit);
  else
    j.number(NAN);  // null
  j.key("end");
  sample_json(j, r.end());
  j.key("initial_mass").number(r.initial_mass).key("mass_lost").number(r.end().failed_mass);
  j.key("mass_lost_fraction").number(r.end().failed_mass / r.initial_mass);
  j.key("missing_mass").number(r.missing_mass());
  j.key("zero_components").string(r.zero_components).key("frames").integer(r.history.size());
  j.key("symmetry");
  write_symmetry_json(j, r.symmetry);
  j.end_object();
  std::printf("%s\n", j.text().c_str());
}

void print_sample(const char* what, const ResidualSample& s) {
  std::printf(
      "  %s t = %.4g us: %.4g m/s along the initial direction, speed %.4g m/s, angle %.3g deg "
      "to it; v = (%.4g, %.4g, %.4g) m/s\n",
      what, s.time * 1e6, s.v_along, s.v.norm(), s.angle, s.v.x(), s.v.y(), s.v.z());
}

void print_residual_text(const ResidualResult& r) {
  std::string targets;
  for (const std::string& t : r.targets) targets += (targets.empty() ? "'" : ", '") + t + "'";
  const Vec3& d = r.direction;
  std::printf(
      "Residual velocity of '%s' through %s: initial direction (%.4g, %.4g, %.4g), %.4g m/s "
      "along it\n",
      r.body.c_str(), targets.c_str(), d.x(), d.y(), d.z(), r.history.front().v_along);
  if (!r.symmetry.describe().empty()) std::printf("  %s\n", r.symmetry.describe().c_str());
  if (!r.zero_components.empty())
    std::printf(
        "  velocity component %s: zero by construction (normal to a mirror plane, or the radius "
        "of an axisymmetric model), not measured\n",
        r.zero_components.c_str());
  std::printf(
      "  the targets' far face along %s%c: %c = %.4g mm (particle centres; the tail has left "
      "when past it)\n",
      r.sign > 0 ? "+" : "-", "xyz"[r.axis], "xyz"[r.axis], r.sign * r.far_face * 1e3);
  if (r.exit)
    print_sample("tail left the target at", *r.exit);
  else
    std::printf("  the tail has not left the target by the last frame\n");
  print_sample("residual at the end,", r.end());
  const double lost = r.end().failed_mass;
  std::printf("  mass lost to failure: %.4g g of %.4g g (%.3g%%)", lost * 1e3, r.initial_mass * 1e3,
              100 * lost / r.initial_mass);
  if (r.missing_mass() > 0) std::printf("; %.4g g left the domain", r.missing_mass() * 1e3);
  std::printf("\n");
}

void write_residual_csv(const ResidualResult& r, const std::string& path) {
  std::FILE* out = open_output(path);
  std::fprintf(out,
               "time_s,v_x,v_y,v_z,v_along,speed,angle_deg,mass_kg,failed_mass_kg,tail_m,"
               "tail_out\n");
  for (const ResidualSample& s : r.history) {
    std::fprintf(out, "%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%d\n", s.time,
                 s.v.x(), s.v.y(), s.v.z(), s.v_along, s.v.norm(), s.angle, s.mass, s.failed_mass,
                 s.tail, s.out ? 1 : 0);
    check_written(out, path);
  }
  close_output(out, path);
}

}  // namespace

int post_residual(const ResidualArgs& a, const ResidualPlot& plot) {
  if (!a.plot.empty() && !plot) throw std::logic_error("post_residual: --plot without a plotter");
  const std::string& path = a.input;
  ResidualOptions opt;
  opt.body = a.body;
  opt.target = a.target;
  std::optional<Scene> scene;
  std::optional<ResidualMeter> meter;
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
    meter->add(f);
  };
  const StreamSummary s = read_stream(path, v);
  if (!meter) {
    std::fprintf(stderr, "mpm-post: error: %s holds no frame to measure\n",
                 input_name(path).c_str());
    return kExitBadInput;
  }
  const ResidualResult& r = meter->result();
  if (!a.output.empty()) write_residual_csv(r, a.output);
  if (!a.plot.empty()) plot(r, a.plot);
  if (a.json)
    print_residual_json(r);
  else
    print_residual_text(r);
  std::fflush(stdout);
  return conclude(path, s, frames);
}

}  // namespace mpm
