// mpm-post: what users report from a result stream.
//   mpm-post summary run.mpm            mpm-post history run.mpm -o history.csv
//   mpm-post scene run.mpm > scene.toml
//   mpm-post vtk run.mpm -o out/        mpm-post taylor run.mpm --json
//   mpm-post particles run.mpm --columns x,sigma -o last.csv
//   mpm-post render run.mpm -o bar.png --field eps_p
//   mpm-post profile run.mpm --field sigma --component xx --time 9us   (CSV, or --json)
#include <CLI/CLI.hpp>

#include "mpm/core/cli.hpp"
#include "mpm/core/error.hpp"
#include "mpm/core/version.hpp"
#include "mpm/post/command_io.hpp"
#include "mpm/post/commands.hpp"
#include "mpm/post/vtk/vtk_commands.hpp"

namespace {

CLI::App* add_summary(CLI::App& app, mpm::SummaryArgs& a) {
  auto* sub = app.add_subcommand("summary", "what a stream holds: frames, history, end status");
  sub->add_option("input", a.input, "stream, - for stdin")->capture_default_str();
  sub->add_flag("--json", a.json, "print JSON");
  return sub;
}

CLI::App* add_scene(CLI::App& app, mpm::SceneArgs& a) {
  auto* sub = app.add_subcommand(
      "scene", "the scene a model or result holds, as TOML (with the --set overrides applied)");
  sub->add_option("input", a.input, "stream, - for stdin")->capture_default_str();
  sub->add_option("-o,--output", a.output, "TOML file, - for stdout")->capture_default_str();
  return sub;
}

/// --digits of the CSV commands: significant digits of the values written.
void add_digits(CLI::App* sub, int& digits) {
  sub->add_option("--digits", digits, "significant digits (17: every bit of a double)")
      ->check(CLI::Range(1, 17))
      ->capture_default_str();
}

CLI::App* add_history(CLI::App& app, mpm::HistoryArgs& a) {
  auto* sub =
      app.add_subcommand("history", "time histories as CSV (energies, momentum, wall forces)");
  sub->add_option("input", a.input, "stream, - for stdin")->capture_default_str();
  sub->add_option("-o,--output", a.output, "CSV file, - for stdout")->capture_default_str();
  sub->add_option("--columns", a.columns, "columns to print (default all)")->delimiter(',');
  add_digits(sub, a.digits);
  return sub;
}

CLI::App* add_particles(CLI::App& app, mpm::ParticlesArgs& a) {
  auto* sub = app.add_subcommand("particles",
                                 "the particles of one frame as CSV (one column per component)");
  sub->add_option("input", a.input, "stream, - for stdin")->capture_default_str();
  sub->add_option("-o,--output", a.output, "CSV file, - for stdout")->capture_default_str();
  sub->add_option("--frame", a.frame, "frame index (0 = first) or 'last'")->capture_default_str();
  sub->add_option("--columns", a.columns, "particle columns (default all), e.g. x,sigma")
      ->delimiter(',');
  add_digits(sub, a.digits);
  return sub;
}

CLI::App* add_vtk(CLI::App& app, mpm::VtkArgs& a) {
  auto* sub = app.add_subcommand("vtk", "ParaView files: a .vtu per frame and a .pvd series");
  sub->add_option("input", a.input, "stream, - for stdin")->capture_default_str();
  sub->add_option("-o,--output", a.directory, "directory")->capture_default_str();
  sub->add_option("--name", a.name, "file name prefix")->capture_default_str();
  sub->add_option("--every", a.every, "write every Nth frame (the final one always)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  return sub;
}

/// The --symmetry option of the measures and render; `what` says what the planes change.
void add_symmetry(CLI::App* sub, std::string& symmetry, const std::string& what) {
  sub->add_option("--symmetry", symmetry,
                  "mirror planes of a quarter or half model, e.g. \"x = 0, y = 0 mm\", or "
                  "\"none\"" +
                      what + " (default: the scene's slip faces through a body)");
}

CLI::App* add_taylor(CLI::App& app, mpm::TaylorArgs& a) {
  auto* sub = app.add_subcommand(
      "taylor", "final length L and foot diameter D (mean caliper width) of a bar against a wall");
  sub->add_option("input", a.input, "stream, - for stdin")->capture_default_str();
  sub->add_option("--body", a.body, "body name (default: the first)");
  sub->add_option("--axis", a.axis, "bar axis x, y or z (default: its longest extent)");
  sub->add_option(
      "--wall", a.wall,
      "wall position along the axis, e.g. \"0 mm\" (default: the constrained domain face)");
  sub->add_flag("--surface", a.surface,
                "measure the surface (centres + half a particle spacing; on a graded grid the "
                "spacing of the level the end and the foot lie on) instead of particle centres");
  sub->add_option("--expect-L", a.expect_L,
                  "reference length, e.g. \"16.2 mm\", to print the difference");
  sub->add_option("--expect-D", a.expect_D, "reference diameter, e.g. \"13.5 mm\"");
  add_symmetry(sub, a.symmetry, "; the measure is the whole body's");
  sub->add_flag("--json", a.json, "print JSON (SI units)");
  return sub;
}

CLI::App* add_debris(CLI::App& app, mpm::DebrisArgs& a) {
  auto* sub =
      app.add_subcommand("debris", "front and width of a debris cloud behind a struck plate");
  sub->add_option("input", a.input, "stream, - for stdin")->capture_default_str();
  sub->add_option("--time", a.time,
                  "the frame nearest this time, e.g. \"30.6 us\" (default: the last)");
  sub->add_option("--axis", a.axis, "impact axis x, y or z (default: the projectile's velocity)");
  sub->add_option(
      "--plane", a.plane,
      "reference plane along the axis, e.g. \"6.36 mm\" (default: the target's rear face)");
  sub->add_option("--face", a.face,
                  "the target's face the front is measured from: rear or impact (the cloud is "
                  "what lies behind the rear face either way)")
      ->check(CLI::IsMember({"rear", "impact"}))
      ->capture_default_str();
  sub->add_option("--target", a.target, "target body (default: the first body at rest)");
  sub->add_option("--projectile", a.projectile, "projectile body (default: the fastest body)");
  sub->add_option(
         "--percentile", a.percentile,
         "which particles count: the front and width reported are this percentile of the "
         "cloud's distances, by mass (stray particles beyond it are ignored; max and 99/99.5/99.9 "
         "are always printed; axisymmetric: the axis is y, each ring weighs its mass)")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  sub->add_option("--min-fragment", a.min_fragment,
                  "which particles count: only those of fragments of at least this many particles "
                  "(particles closer than --link are one fragment); 1: all")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  sub->add_option("--link", a.link,
                  "linking length of fragments, e.g. \"1 mm\" (default: the grid's cell size)");
  sub->add_flag("--escaped", a.escaped,
                "also count the particles that left the domain by the frame's time (the run's "
                "escape records), and those of them that left behind the plane");
  sub->add_option("--expect-front", a.expect_front, "reference front, e.g. \"200 mm\"");
  sub->add_option("--expect-width", a.expect_width, "reference width, e.g. \"145 mm\"");
  add_symmetry(sub, a.symmetry, "; the measure is the whole body's");
  sub->add_flag("--json", a.json, "print JSON (SI units)");
  return sub;
}

CLI::App* add_crater(CLI::App& app, mpm::CraterArgs& a) {
  auto* sub = app.add_subcommand(
      "crater",
      "depth and diameter of a target's crater (or the hole when perforated) on the impact "
      "axis, and how deep each body went");
  sub->add_option("input", a.input, "stream, - for stdin")->capture_default_str();
  sub->add_option("--time", a.time,
                  "the frame nearest this time, e.g. \"40 us\" (default: the last)");
  sub->add_option("--target", a.target, "target body (default: the first body at rest)");
  sub->add_option("--projectile", a.projectile,
                  "projectile body: the crater's axis runs through its initial centre (default: "
                  "the fastest body)");
  sub->add_option("--axis", a.axis, "impact axis x, y or z (default: the projectile's velocity)");
  add_symmetry(sub, a.symmetry, "");
  sub->add_flag("--json", a.json, "print JSON (SI units)");
  return sub;
}

CLI::App* add_residual(CLI::App& app, mpm::ResidualArgs& a) {
  auto* sub = app.add_subcommand(
      "residual",
      "a projectile's velocity through a target: residual velocity when its tail has left the "
      "target and at the end, exit angle, mass lost to failure");
  sub->add_option("input", a.input, "stream, - for stdin")->capture_default_str();
  sub->add_option("--body", a.body, "the projectile (default: the fastest body at t = 0)");
  sub->add_option("--target", a.target, "the target body (default: every other body)");
  sub->add_option("-o,--output", a.output,
                  "the history as CSV (time, velocity, along the initial direction, speed, "
                  "angle, mass, failed mass, tail), - for stdout");
  sub->add_option("--plot", a.plot,
                  "a PNG chart of the history (speed and along the initial direction against "
                  "time, off-screen)");
  add_symmetry(sub, a.symmetry, "; the velocity is the whole body's");
  sub->add_flag("--json", a.json, "print JSON (SI units)");
  return sub;
}

CLI::App* add_profile(CLI::App& app, mpm::ProfileArgs& a) {
  auto* sub =
      app.add_subcommand("profile", "a field along a line (stress waves, shocks), CSV or JSON");
  sub->add_option("input", a.input, "stream, - for stdin")->capture_default_str();
  sub->add_option("-o,--output", a.output, "CSV (or JSON) file, - for stdout")
      ->capture_default_str();
  sub->add_option("--field", a.profile.field,
                  "a column (sigma, v, eps_p, ...) or pressure, von_mises, speed")
      ->capture_default_str();
  sub->add_option("--component", a.component,
                  "xx, yy, zz, yz, xz, xy (tensors), x, y, z (vectors), an index, or magnitude")
      ->capture_default_str();
  sub->add_option("--along", a.along,
                  "the line's direction when --from/--to are not given: x, y or z, over the "
                  "particles' extent through their centroid")
      ->capture_default_str();
  sub->add_option("--from", a.from, "start of the line, e.g. \"0 0 0 mm\"");
  sub->add_option("--to", a.to, "end of the line");
  sub->add_option(
      "--radius", a.radius,
      "leave out particles farther than this from the line, e.g. \"1 mm\" (default: none)");
  sub->add_option("--body", a.body, "only this body's particles");
  sub->add_option("--bins", a.profile.bins,
                  "average in this many equal bins along the line (default: one row per particle)");
  sub->add_option("--weight", a.weight,
                  "what a particle weighs in a bin's mean (and the weight column): volume "
                  "(m/rho: a mean over space) or mass (m: a mean over material); --grid: mass")
      ->check(CLI::IsMember({"volume", "mass"}))
      ->capture_default_str();
  sub->add_flag("--grid", a.grid,
                "on the grid: project the field onto the run's grid nodes (linear shape "
                "functions, mass-weighted) and profile the nodes near the line");
  sub->add_option("--time", a.times, "the frame nearest this time, e.g. 9us (repeatable)");
  sub->add_option("--frame", a.frames,
                  "frame index, 0 = first (repeatable); default: the last frame");
  sub->add_flag("--json", a.json, "print JSON (SI units)");
  return sub;
}

CLI::App* add_render(CLI::App& app, mpm::RenderArgs& a) {
  auto* sub =
      app.add_subcommand("render", "PNG picture of a frame, off-screen (works without a display)");
  sub->add_option("input", a.input, "stream, - for stdin")->capture_default_str();
  sub->add_option("-o,--output", a.output, "PNG file")->capture_default_str();
  sub->add_option("--frame", a.frame, "frame index (0 = first) or 'last'")->capture_default_str();
  sub->add_option("--time", a.time, "the frame nearest this time, e.g. \"30.6 us\"");
  sub->add_option("--field", a.picture.field,
                  "colour by: a column (eps_p, rho, e, ...) or pressure, von_mises, speed")
      ->capture_default_str();
  sub->add_option("--component", a.picture.component,
                  "component of a vector field (-1: magnitude)");
  sub->add_option("--view", a.picture.view,
                  "orthographic view: side (looking along -y), front (-x), top (-z), iso (from "
                  "+x+y+z), or symmetry (square on to a mirror plane of a quarter or half model: "
                  "the section of the whole body there, e.g. through a crater)")
      ->check(CLI::IsMember({"side", "front", "top", "iso", "symmetry"}))
      ->capture_default_str();
  sub->add_option("--section", a.picture.section,
                  "cut at a plane in absolute coordinates, e.g. \"x = 0\" or \"y = 2.5 mm\" "
                  "(plain numbers in m): keeps the side with more particles and looks square at "
                  "the cut");
  add_symmetry(sub, a.symmetry, "; the picture shows the whole body");
  sub->add_option("--clip", a.picture.clip,
                  "keep one side of a plane given as an OFFSET FROM THE MODEL'S CENTROID, e.g. "
                  "\"y>0\" (the centroid's side), \"y>2mm\"; for absolute planes use --section");
  sub->add_option("--size", a.size, "WIDTHxHEIGHT in pixels")->capture_default_str();
  sub->add_option("--range", a.range, "colour range MIN:MAX (SI units)");
  sub->add_option("--title", a.picture.title, "title text");
  sub->add_option("--radius", a.picture.point_radius,
                  "particle radius in m (default from mass and density)");
  sub->add_flag(
      "--half", a.half,
      "axisymmetric frames: draw the half plane r >= 0 only (default: the whole section, mirrored "
      "about the axis)");
  return sub;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "mpm-post: read a result stream (from mpm-run) and report.\n"
      "INPUT is a stream file or - for stdin. --json on measurements prints JSON.\n"
      "Exit status: 0 done, 2 bad input or damaged stream (the frames before the\n"
      "damage are still used), 3 the run was unstable, 4 write failure,\n"
      "5 the run stopped: a particle left the domain.",
      "mpm-post"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("mpm-post ") + mpm::kVersion);
  mpm::SummaryArgs summary_args;
  mpm::SceneArgs scene_args;
  mpm::HistoryArgs history_args;
  mpm::ParticlesArgs particles_args;
  mpm::VtkArgs vtk_args;
  mpm::TaylorArgs taylor_args;
  mpm::DebrisArgs debris_args;
  mpm::ProfileArgs profile_args;
  mpm::CraterArgs crater_args;
  mpm::RenderArgs render_args;
  mpm::ResidualArgs residual_args;
  const auto* summary = add_summary(app, summary_args);
  const auto* scene = add_scene(app, scene_args);
  const auto* history = add_history(app, history_args);
  const auto* particles = add_particles(app, particles_args);
  const auto* vtk = add_vtk(app, vtk_args);
  const auto* taylor = add_taylor(app, taylor_args);
  const auto* debris = add_debris(app, debris_args);
  const auto* profile = add_profile(app, profile_args);
  const auto* crater = add_crater(app, crater_args);
  const auto* render = add_render(app, render_args);
  const auto* residual = add_residual(app, residual_args);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : mpm::kExitBadInput;
  }
  return mpm::guarded_main("mpm-post", [&]() -> int {
    mpm::ignore_sigpipe();
    // No subcommand writes over the stream it reads.
    if (*scene) mpm::check_output_file(scene_args.output, {scene_args.input});
    if (*history) mpm::check_output_file(history_args.output, {history_args.input});
    if (*particles) mpm::check_output_file(particles_args.output, {particles_args.input});
    if (*profile) mpm::check_output_file(profile_args.output, {profile_args.input});
    if (*render) mpm::check_output_file(render_args.output, {render_args.input});
    if (*residual && !residual_args.output.empty())
      mpm::check_output_file(residual_args.output, {residual_args.input});
    if (*residual && !residual_args.plot.empty())
      mpm::check_output_file(residual_args.plot, {residual_args.input});
    // Measures need a result: a model from mpm-prep is refused, naming what to run.
    if (*history) mpm::require_result(history_args.input, "history");
    if (*taylor) mpm::require_result(taylor_args.input, "taylor");
    if (*debris) mpm::require_result(debris_args.input, "debris");
    if (*crater) mpm::require_result(crater_args.input, "crater");
    if (*profile) mpm::require_result(profile_args.input, "profile");
    if (*render) mpm::require_result(render_args.input, "render");
    if (*residual) mpm::require_result(residual_args.input, "residual");
    if (*summary) return mpm::post_summary(summary_args);
    if (*scene) return mpm::post_scene(scene_args);
    if (*history) return mpm::post_history(history_args);
    if (*particles) return mpm::post_particles(particles_args);
    if (*vtk) return mpm::post_vtk(vtk_args);
    if (*taylor) return mpm::post_taylor(taylor_args);
    if (*debris) return mpm::post_debris(debris_args);
    if (*profile) return mpm::post_profile(profile_args);
    if (*crater) return mpm::post_crater(crater_args);
    if (*residual) {
      if (residual_args.plot.empty()) return mpm::post_residual(residual_args);
      mpm::ensure_display(argc, argv);  // before reading: a re-run under xvfb reads stdin again
      return mpm::post_residual(residual_args,
                                [](const mpm::ResidualResult& r, const std::string& png) {
                                  mpm::plot_residual_png(r, png);
                                });
    }
    if (*render) {
      mpm::ensure_display(argc, argv);  // before reading: a re-run under xvfb reads stdin again
      return mpm::post_render(render_args);
    }
    return mpm::kExitBadInput;
  });
}
