// mpm-post vtk and render: ParaView files and PNG pictures of a result stream.
#include "mpm/post/vtk/vtk_commands.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "mpm/core/error.hpp"
#include "mpm/post/arguments.hpp"
#include "mpm/post/command_io.hpp"
#include "mpm/stream/grid_record.hpp"

namespace mpm {

namespace {

/// The directory of `vtk`, created when missing; throws when it is a file or cannot be made.
void make_directory(const std::string& dir) {
  std::error_code ec;
  if (std::filesystem::exists(dir, ec) && !std::filesystem::is_directory(dir, ec))
    throw InputError("-o " + dir,
                     "exists and is not a directory (vtk writes a directory of .vtu "
                     "files and a .pvd series)");
  std::filesystem::create_directories(dir, ec);
  if (ec) throw IoError("cannot create the directory '" + dir + "': " + ec.message());
}

/// The picture options of the command-line values: size and range parsed.
RenderOptions picture_options(const RenderArgs& a) {
  RenderOptions o = a.picture;
  if (std::sscanf(a.size.c_str(), "%dx%d", &o.width, &o.height) != 2 || o.width < 16 ||
      o.height < 16)
    throw InputError("--size", "expected WIDTHxHEIGHT in pixels, got '" + a.size + "'");
  if (!a.range.empty() && std::sscanf(a.range.c_str(), "%lf:%lf", &o.range_min, &o.range_max) == 2)
    o.range_given = true;
  else if (!a.range.empty())
    throw InputError("--range", "expected MIN:MAX in the field's SI unit, got '" + a.range + "'");
  return o;
}

}  // namespace

int post_vtk(const VtkArgs& a) {
  const std::string& dir = a.directory;
  const std::string& name = a.name;
  make_directory(dir);
  std::vector<std::pair<double, std::string>> entries, bars;
  std::size_t index = 0;
  std::optional<Frame> last;  // the frame just written: the REBR record after it is its rebar
  StreamVisitor v;
  v.frame = [&](Frame&& f) {
    last.reset();
    if (index++ % std::size_t(a.every) != 0 && !(f.flags & kFrameFinal)) return;
    const int dim = f.columns.at("x").info().components;
    char file[256];
    std::snprintf(file, sizeof file, "%s_%04zu.vtu", name.c_str(), entries.size());
    write_vtu(f, dim, (std::filesystem::path(dir) / file).string());
    entries.emplace_back(f.time, file);
    write_pvd(entries, (std::filesystem::path(dir) / (name + ".pvd")).string());
    last = std::move(f);
  };
  // Rebar: each frame's elements as <name>_rebar_NNNN.vtu (line cells), in <name>_rebar.pvd.
  v.rebar = [&](Frame&& e) {
    if (!last) return;
    char file[256];
    std::snprintf(file, sizeof file, "%s_rebar_%04zu.vtu", name.c_str(), bars.size());
    write_rebar_vtu(rebar_lines(*last, e), e.time, e.step,
                    (std::filesystem::path(dir) / file).string());
    bars.emplace_back(e.time, file);
    write_pvd(bars, (std::filesystem::path(dir) / (name + "_rebar.pvd")).string());
    last.reset();
  };
  // Graded grids: each GRID record as <name>_grid_NNNN.vtu, listed by time in <name>_grid.pvd.
  std::vector<std::pair<double, std::string>> grids;
  v.grid = [&](std::vector<std::byte>&& payload) {
    GridMesh mesh;
    try {
      mesh = decode_grid(payload);
    } catch (const StreamError& e) {
      throw StreamError(input_name(a.input), e.message());
    }
    char file[256];
    std::snprintf(file, sizeof file, "%s_grid_%04zu.vtu", name.c_str(), grids.size());
    write_grid_vtu(mesh, (std::filesystem::path(dir) / file).string());
    grids.emplace_back(mesh.time, file);
    write_pvd(grids, (std::filesystem::path(dir) / (name + "_grid.pvd")).string());
  };
  const StreamSummary s = read_stream(a.input, v);
  std::fprintf(stderr, "mpm-post: wrote %zu frame(s) and %s\n", entries.size(),
               (std::filesystem::path(dir) / (name + ".pvd")).string().c_str());
  if (!bars.empty())
    std::fprintf(stderr,
                 "mpm-post: wrote %zu rebar frame(s) and %s (line cells: axial_stress, "
                 "plastic_strain, eroded)\n",
                 bars.size(),
                 (std::filesystem::path(dir) / (name + "_rebar.pvd")).string().c_str());
  if (!grids.empty())
    std::fprintf(stderr, "mpm-post: wrote %zu graded grid(s) and %s (cell field 'level')\n",
                 grids.size(),
                 (std::filesystem::path(dir) / (name + "_grid.pvd")).string().c_str());
  return conclude(a.input, s, index);
}

int post_render(const RenderArgs& a) {
  const std::string& path = a.input;
  RenderOptions o = picture_options(a);
  const long want = option_frame(a.frame);
  std::optional<double> at;
  if (!a.time.empty()) at = option_quantity(a.time, dim::time, "--time");
  std::optional<Frame> chosen;
  std::optional<Scene> scene;
  long index = 0;
  double best = 1e300;
  bool chosen_now = false;  // the last frame read is the chosen one (its REBR record follows)
  StreamVisitor v;
  v.scene = [&](const std::string& t) { scene = scene_of(t, path); };
  v.frame = [&](Frame&& f) {
    const long k = index++;
    chosen_now = false;
    if (at) {
      const double d = std::abs(f.time - *at);
      if (d < best) best = d, chosen = std::move(f), chosen_now = true;
    } else if (want < 0 || k == want) {
      chosen = std::move(f), chosen_now = true;
    }
    if (chosen_now) o.rebar = RebarLines{};
  };
  v.rebar = [&](Frame&& e) {
    if (chosen_now) o.rebar = rebar_lines(*chosen, e);
    chosen_now = false;
  };
  const StreamSummary s = read_stream(path, v);
  if (!chosen) {
    std::fprintf(stderr, "mpm-post: error: %s has no frame %s (it holds %ld)\n",
                 input_name(path).c_str(), a.frame.c_str(), index);
    return kExitBadInput;
  }
  const int dim = chosen->columns.at("x").info().components;
  o.axisymmetric = scene && scene->axisymmetric && dim == 2;
  if (scene) o.symmetry = measure_symmetry(a.symmetry, *scene);  // the whole body
  if (o.axisymmetric && !a.half)  // the whole section through the axis
    o.symmetry.planes.insert(o.symmetry.planes.begin(), MirrorPlane{0, 0.0});
  render_png(*chosen, dim, o, a.output);
  // The time in us for impact runs, in s for slow ones (forming, the dimensionless V7 scenes).
  const bool slow = chosen->time >= 1e-2;
  std::fprintf(stderr, "mpm-post: wrote %s (frame at t = %.4g %s, %zu particles, coloured by %s)\n",
               a.output.c_str(), slow ? chosen->time : chosen->time * 1e6, slow ? "s" : "us",
               chosen->columns.size(), o.field.c_str());
  return conclude(path, s, std::size_t(index));
}

}  // namespace mpm
