#include "mpm/prep/prep.hpp"

#include <omp.h>
#include <toml++/toml.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <sstream>

#include "mpm/core/cli.hpp"
#include "mpm/core/error.hpp"
#include "mpm/core/version.hpp"
#include "mpm/grid/lattice.hpp"
#include "mpm/grid/sparse_grid.hpp"
#include "mpm/prep/checks.hpp"
#include "mpm/prep/face_offsets.hpp"
#include "mpm/prep/graded_voxelise.hpp"
#include "mpm/prep/initial_fields.hpp"
#include "mpm/prep/rebar.hpp"
#include "mpm/prep/region.hpp"
#include "mpm/prep/resources.hpp"
#include "mpm/prep/scene_needs.hpp"
#include "mpm/prep/target_error.hpp"
#include "mpm/prep/voxelise.hpp"
#include "mpm/scene/particles.hpp"
#include "mpm/solver/materials/material.hpp"
#include "mpm/solver/materials/models.hpp"
#include "mpm/stream/stream.hpp"

namespace mpm {

namespace {

/// The scene text with grid.domain set to the lattice's (SI numbers) and no padding, so that
/// mpm-run and mpm-post rebuild the same lattice without the bodies' geometry.
std::string with_explicit_domain(const std::string& text, const Lattice& lat) {
  toml::table doc = toml::parse(text);
  toml::table* grid = doc["grid"].as_table();
  if (!grid) grid = doc.insert_or_assign("grid", toml::table{}).first->second.as_table();
  grid->erase("padding");
  const Vec3 hi = lat.max();
  toml::array lo_a, hi_a;
  for (int a = 0; a < lat.dim; ++a) {
    lo_a.push_back(lat.origin[a]);
    hi_a.push_back(hi[a]);
  }
  grid->insert_or_assign("domain", toml::table{{"min", lo_a}, {"max", hi_a}});
  std::ostringstream o;
  o << doc;
  return o.str() + "\n";
}

/// Bytes of the sparse grid at the start: its nodes (8 + 3 D 8 bytes), the cell-to-key table
/// of its box (4 bytes a cell) and each active cell's node list and layer.
template <int D>
double sparse_grid_bytes(const Scene& scene, const Lattice& lattice, const ColumnStore& cols) {
  SparseGrid<D> g(lattice, scene.boundary);
  g.fit(cols.get<Vec<D>>(col::x), cols.size());
  return double(g.nodes()) * (8 + 3 * D * 8) + double(g.box_cells()) * 4 +
         double(g.key_count()) * 4 * (kCorners<D> + 1);
}

std::string mm(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", x * 1e3);
  return b;
}

/// What mpm-prep estimates of a run: its first stable step, its steps and its memory.
struct Estimates {
  double speed = 0;           ///< fastest signal, m/s (behind the impact shock when faster)
  double speed_start = 0;     ///< fastest signal at the start, c + |v|, m/s
  double dt = 0;              ///< first stable step, s
  double steps = 0;           ///< steps to solver.end_time
  double bytes_particle = 0;  ///< memory of a particle, bytes
  double bytes_grid = 0;      ///< memory of the grid (window, sparse or graded), bytes
};

/// The signal speeds of the particles (m/s). The signal speed is the larger of the unshocked
/// c + |v| and, for impacts, the speed behind the shock the fastest particle of each material
/// drives into like material at rest (u_p = |v| / 2), where the compressed, heated material
/// carries faster waves and the bulk viscosity widens them: at hypervelocity that is what sets
/// the step (V4: twice the unshocked estimate).
void signal_speeds(const Scene& scene, const ColumnStore& cols, Estimates& e) {
  double speed = 0, speed_start = 0;
  std::vector<Material> materials;
  std::vector<double> c(scene.materials.size()), v_max(scene.materials.size(), 0.0);
  for (std::size_t k = 0; k < c.size(); ++k) {
    materials.emplace_back(scene.materials[k], scene.solver);
    c[k] = materials[k].reference_wave_speed();
  }
  const auto* mat = cols.get<std::uint8_t>(col::material);
  const auto* v = reinterpret_cast<const double*>(cols.at(col::v).data());
  const int d = scene.dimension;
  for (std::size_t i = 0; i < cols.size(); ++i) {
    if (mat[i] == kRebarNode) continue;  // the truss wave's step: rebar_time_step
    double s2 = 0;
    for (int a = 0; a < d; ++a) s2 += v[i * d + a] * v[i * d + a];
    // Rigid bodies (kRigidMaterial) carry no waves: only their speed counts.
    const double ci = mat[i] == kRigidMaterial ? 0.0 : c[mat[i]];
    speed_start = std::max(speed_start, ci + std::sqrt(s2));
    if (mat[i] != kRigidMaterial) v_max[mat[i]] = std::max(v_max[mat[i]], std::sqrt(s2));
  }
  speed = speed_start;
  if (scene.solver.type == SolverType::Explicit)
    for (std::size_t k = 0; k < c.size(); ++k)
      if (v_max[k] > 0) speed = std::max(speed, materials[k].shocked_signal_speed(0.5 * v_max[k]));
  e.speed = speed;
  e.speed_start = speed_start;
}

/// Memory of the grid at the start (bytes): the graded grid's nodes, the sparse grid, or the
/// window around the bodies (cells of the particles' bounding box), 8 + 3 d 8 bytes a node.
double grid_bytes(const Scene& scene, const Lattice& lattice, const ColumnStore& cols,
                  const GradedModel* graded) {
  const int d = scene.dimension;
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  {
    const auto* x = reinterpret_cast<const double*>(cols.at(col::x).data());
    for (std::size_t i = 0; i < cols.size(); ++i)
      for (int a = 0; a < d; ++a)
        lo[a] = std::min(lo[a], x[i * d + a]), hi[a] = std::max(hi[a], x[i * d + a]);
  }
  double nodes = 1;
  for (int a = 0; a < d; ++a) nodes *= std::floor((hi[a] - lo[a]) / lattice.h) + 4;
  if (graded) nodes = double(graded->nodes);  // the graded grid has no window
  double bytes_grid = nodes * grid_node_bytes(d);
  if (scene.grid.sparse)
    bytes_grid = d == 3 ? sparse_grid_bytes<3>(scene, lattice, cols)
                        : sparse_grid_bytes<2>(scene, lattice, cols);
  return bytes_grid;
}

/// Estimates of a run of the model: first stable step, steps to the end, memory.
Estimates estimate_run(const Scene& scene, const Lattice& lattice, const ColumnStore& cols,
                       const GradedModel* graded) {
  Estimates e;
  signal_speeds(scene, cols, e);
  const double h_min = graded ? graded->h_min : lattice.h;  // the time step's cell
  e.dt = stable_time_step(scene.solver.dt_max, scene.solver.cfl, h_min, e.speed);
  e.steps = std::ceil(scene.solver.end_time / e.dt);
  e.bytes_particle = run_particle_bytes(scene);
  e.bytes_grid = grid_bytes(scene, lattice, cols, graded);
  return e;
}

/// The summary's head: the scene, its lattice and, for a graded grid, its levels.
void print_grid(const Scene& scene, const Lattice& lattice, const GradedModel* graded) {
  const int d = scene.dimension;
  std::fprintf(stderr, "mpm-prep: %s%s%s (%dD%s)\n", scene.source.c_str(),
               scene.title.empty() ? "" : ": ", scene.title.c_str(), d,
               d == 2
                   ? (scene.axisymmetric   ? ", axisymmetric, masses per radian"
                      : scene.plane_stress ? ", plane stress, masses per metre of initial thickness"
                                           : ", plane strain, masses per metre")
                   : "");
  std::fprintf(stderr, "  grid: cell %s mm, domain [%s, %s] x [%s, %s]", mm(lattice.h).c_str(),
               mm(lattice.origin[0]).c_str(), mm(lattice.max()[0]).c_str(),
               mm(lattice.origin[1]).c_str(), mm(lattice.max()[1]).c_str());
  if (d == 3)
    std::fprintf(stderr, " x [%s, %s]", mm(lattice.origin[2]).c_str(),
                 mm(lattice.max()[2]).c_str());
  std::fprintf(stderr, " mm, %d x %d", lattice.cells[0], lattice.cells[1]);
  if (d == 3) std::fprintf(stderr, " x %d", lattice.cells[2]);
  std::fprintf(stderr, " cells\n");
  if (graded) {
    std::fprintf(stderr, "  graded grid: %zu nodes (%zu hanging), %zu transition cells\n",
                 graded->nodes, graded->hanging_nodes, graded->transition_cells);
    for (std::size_t l = 1; l < graded->cells.size(); ++l)
      std::fprintf(stderr, "    level %zu: cell %s mm, %zu cells, %zu particles\n", l,
                   mm(std::ldexp(lattice.h, -int(l - 1))).c_str(), graded->cells[l],
                   graded->particles[l]);
  }
}

/// The mirror images a body's particles stand for: 2 for each slip face of the domain through
/// the middle of the body's box (the symmetry plane of a half or quarter model), else 1.
int mirror_images(const Scene& scene, const Lattice& lattice, const Vec3& lo, const Vec3& hi) {
  if (scene.axisymmetric) return 1;  // its mass is per radian already, of r >= 0
  int images = 1;
  for (int f = 0; f < 2 * scene.dimension; ++f) {
    if (scene.boundary.face[f] != BoundaryType::Slip) continue;
    const int a = f / 2;
    const double plane = f % 2 ? lattice.max()[a] : lattice.origin[a];
    if (std::abs(plane - 0.5 * (lo[a] + hi[a])) <= 1e-6 * (hi[a] - lo[a])) images *= 2;
  }
  return images;
}

/// The summary's table of bodies; returns the particles in all. A body cut through its middle
/// by symmetry planes is compared whole: its mass times its mirror images against the whole
/// body's exact mass (a half model's plate is not 50% short).
std::size_t print_bodies(const Scene& scene, const std::vector<BodyReport>& report,
                         const Lattice& lattice, const BodyBoxes& boxes) {
  std::fprintf(stderr, "  %-14s %-12s %12s %13s %14s %14s %8s\n", "body", "material", "particles",
               "spacing", "mass kg", "exact kg", "error");
  std::size_t total = 0;
  bool mirrored = false;
  const std::size_t shown = report.size() > 24 ? 12 : report.size();  // a table of grains: its head
  for (std::size_t b = 0; b < report.size(); ++b) {
    const BodyReport& r = report[b];
    total += r.particles;
    if (b == shown) std::fprintf(stderr, "  ... %zu bodies more\n", report.size() - shown);
    if (b >= shown) continue;
    const int images = mirror_images(scene, lattice, boxes.lo[b], boxes.hi[b]);
    const double mass = r.mass * images;
    const std::string name = images > 1 ? r.name + " (x" + std::to_string(images) + ")" : r.name;
    mirrored = mirrored || images > 1;
    // On a graded grid a body filling finer levels has their spacings too: coarsest / finest.
    const std::string spacing = r.finest_spacing > 0 && r.finest_spacing < 0.999 * r.spacing
                                    ? mm(r.spacing) + " / " + mm(r.finest_spacing)
                                    : mm(r.spacing);
    std::fprintf(
        stderr, "  %-14s %-12s %12zu %13s mm %14.6g %14.6g %7.2f%%\n", name.c_str(),
        scene.bodies[b].rigid ? "(rigid)" : scene.materials[scene.bodies[b].material].name.c_str(),
        r.particles, spacing.c_str(), mass, r.exact_mass,
        r.exact_mass > 0 ? 100.0 * (mass - r.exact_mass) / r.exact_mass : 0.0);
  }
  std::fprintf(stderr, "  %-14s %-12s %12zu\n", "total", "", total);
  if (mirrored)
    std::fprintf(stderr,
                 "  (x2, x4: the body is cut through its middle by symmetry planes (slip faces); "
                 "its mass is the model's times its mirror images, against the whole body)\n");
  return total;
}

/// The bodies' flat faces that the particles' lattice moves (face_offsets.hpp).
void print_face_offsets(const Scene& scene, const std::vector<FaceOffset>& faces) {
  if (faces.empty()) return;
  std::fprintf(stderr,
               "  faces between the particles' lattice planes, filled to the nearest one (a "
               "domain corner a whole number of particle spacings from a face puts it on one):\n");
  for (const FaceOffset& f : faces) std::fprintf(stderr, "    %s\n", describe(scene, f).c_str());
}

/// The bodies' flat faces that lie inside a cell, not on a node plane (face_offsets.hpp).
void print_face_places(const Scene& scene, const std::vector<FacePlace>& places) {
  if (places.empty()) return;
  std::fprintf(stderr,
               "  faces inside a cell (where a body meets an impact, its face's place against the "
               "node planes can move the result: docs/scene.md, \"Where the faces fall\"):\n");
  for (const FacePlace& f : places) std::fprintf(stderr, "    %s\n", describe(scene, f).c_str());
}

/// Each material's wave speed and the step it alone would allow on the finest cells: a
/// modulus or a density in the wrong unit shows here.
void print_materials(const Scene& scene, double h_min) {
  for (const MaterialSpec& spec : scene.materials) {
    const double c = Material(spec, scene.solver).reference_wave_speed();
    std::fprintf(stderr,
                 "  material %-12s wave speed %.4g m/s (density %.4g kg/m^3, E %.4g GPa): "
                 "step cfl h / c = %.4g ns\n",
                 spec.name.c_str(), c, spec.density, spec.youngs_modulus / 1e9,
                 scene.solver.cfl * h_min / c * 1e9);
    // An opt-in rate law changes what the material is: say so, with what it gives (the reader
    // takes tension_rate for HJC only).
    if (spec.hjc.tension_rate == HjcSpec::TensionRate::MalvarRoss) {
      const auto T_at = [&](double rate) {
        return spec.hjc.T * hjc_tension_dif(spec.hjc, rate) / 1e6;
      };
      std::fprintf(stderr,
                   "    tensile strength %.4g MPa rising with the strain rate (Malvar-Ross for f'c "
                   "%.4g MPa): %.4g MPa at 1 /s, %.4g at 100 /s, %.4g at 1000 /s",
                   spec.hjc.T / 1e6, spec.hjc.fc / 1e6, T_at(1.0), T_at(100.0), T_at(1000.0));
      if (std::isfinite(spec.hjc.tension_dif_max))
        std::fprintf(stderr, ", at most %.4g MPa (x%.4g)",
                     spec.hjc.T * spec.hjc.tension_dif_max / 1e6, spec.hjc.tension_dif_max);
      std::fprintf(stderr, "\n");
    }
    if (spec.strength.model == StrengthModel::Hjc && spec.hjc.damage_length > 0)
      std::fprintf(stderr,
                   "    damage increments averaged over %.4g mm (%.3g finest cells; reaching at "
                   "most %.4g mm each way)\n",
                   spec.hjc.damage_length * 1e3, spec.hjc.damage_length / h_min,
                   2e3 * spec.hjc.damage_length);
  }
}

/// Warnings for bodies that overlap earlier ones: the points of a body inside an earlier
/// body are not created (earlier bodies win), so the later body loses that volume.
void overlap_warnings(const Scene& scene, const std::vector<BodyReport>& report,
                      std::vector<std::string>& warnings) {
  const int d = scene.dimension;
  for (std::size_t b = 0; b < report.size(); ++b) {
    const BodyReport& r = report[b];
    if (r.skipped_overlap == 0) continue;
    const double lost = double(r.skipped_overlap) * std::pow(r.spacing, d);
    char text[160];
    std::snprintf(text, sizeof text, "%zu points (%.3g%% of the body, about %.4g %s) ",
                  r.skipped_overlap,
                  100.0 * double(r.skipped_overlap) / double(r.skipped_overlap + r.particles),
                  lost * std::pow(1e3, d), d == 3 ? "mm^3" : "mm^2 of its section");
    warnings.push_back("body '" + r.name + "' overlaps earlier bodies: " + text +
                       "lie inside them and were not created (earlier bodies win)");
  }
}

/// Prints warnings on stderr.
void print_warnings(const std::vector<std::string>& warnings) {
  for (const std::string& w : warnings) std::fprintf(stderr, "mpm-prep: warning: %s\n", w.c_str());
}

/// The summary's estimates of a run of `total` particles, and warnings.
void print_estimates(const Scene& scene, const Estimates& e, std::size_t total) {
  if (e.speed > e.speed_start * (1 + 1e-9))
    std::fprintf(stderr,
                 "  time step: about %.4g ns (cfl %g, fastest signal %.0f m/s behind the impact "
                 "shock, %.0f m/s at the start), about %.0f steps to %.4g us\n",
                 e.dt * 1e9, scene.solver.cfl, e.speed, e.speed_start, e.steps,
                 scene.solver.end_time * 1e6);
  else
    std::fprintf(stderr,
                 "  time step: about %.4g ns (cfl %g, fastest signal c + |v| = %.0f m/s), about "
                 "%.0f steps to %.4g us\n",
                 e.dt * 1e9, scene.solver.cfl, e.speed, e.steps, scene.solver.end_time * 1e6);
  std::fprintf(stderr,
               "  memory of a run: about %.0f bytes a particle, %.1f MB for particles and %.1f "
               "MB for the grid %s; %.3g million particle-steps\n",
               e.bytes_particle, e.bytes_particle * double(total) / 1e6, e.bytes_grid / 1e6,
               scene.grid.sparse ? "(sparse, at the start)" : "window",
               double(total) * e.steps / 1e6);
  if (scene.solver.cfl > 1.0)
    std::fprintf(stderr, "  warning: solver.cfl = %g exceeds 1; explicit MPM is then unstable\n",
                 scene.solver.cfl);
  if (e.steps > 1e8 && scene.solver.type == SolverType::Explicit)
    std::fprintf(stderr,
                 "  warning: about %.3g explicit steps; check the materials' density and moduli, "
                 "grid.cell_size, solver.dt_max and solver.end_time\n",
                 e.steps);
}

/// The summary's table of rebar: per [[rebar]] entry its bars, elements, nodes and mass
/// against the exact mass rho A L_total.
void print_rebar(const Scene& scene, const std::vector<RebarReport>& report) {
  std::fprintf(stderr, "  %-14s %-12s %6s %9s %9s %10s %14s %14s %8s\n", "rebar", "material",
               "bars", "elements", "nodes", "element", "mass kg", "exact kg", "error");
  for (std::size_t r = 0; r < report.size(); ++r) {
    const RebarReport& p = report[r];
    std::fprintf(stderr, "  %-14s %-12s %6zu %9zu %9zu %7s mm %14.6g %14.6g %7.2f%%\n",
                 scene.rebars[r].loc.key.c_str(),
                 scene.materials[scene.rebars[r].material].name.c_str(), p.bars, p.elements,
                 p.nodes, mm(p.element_length).c_str(), p.mass, p.exact_mass,
                 p.exact_mass > 0 ? 100.0 * (p.mass - p.exact_mass) / p.exact_mass : 0.0);
  }
}

/// The truss wave's step, cfl L_e / (sqrt(E / rho) + |v|) over the shortest element of each
/// [[rebar]] entry, when it is shorter than the particles' (the estimate then follows it).
void rebar_time_step(const Scene& scene, const std::vector<RebarReport>& report, Estimates& e) {
  for (std::size_t r = 0; r < report.size(); ++r) {
    const RebarSpec& b = scene.rebars[r];
    const MaterialSpec& m = scene.materials[b.material];
    const double c = std::sqrt(m.youngs_modulus / m.density) + scene.bodies[b.body].velocity.norm();
    const double dt = std::min(scene.solver.dt_max, scene.solver.cfl * report[r].shortest / c);
    if (report[r].elements > 0 && dt < e.dt) e.dt = dt, e.speed = e.speed_start = c;
  }
  e.steps = std::ceil(scene.solver.end_time / e.dt);
}

/// Writes the model stream: the scene `text`, the info (tool, version, seconds since t0, the
/// bodies), the GRID record of a graded grid, the particles and the rebar's elements (a REBR
/// record, when the scene has rebar).
void write_model(const PrepOptions& opt, const Scene& scene, const std::string& text,
                 const std::vector<BodyReport>& report, const GradedModel* graded, ColumnStore cols,
                 ColumnStore rebar, double t0) {
  std::vector<std::string> inputs{opt.scene};
  for (const auto& b : scene.bodies)
    if (!b.mesh_path.empty()) inputs.push_back(b.mesh_path);
  for (const auto& b : scene.rebars)
    if (!b.path.empty()) inputs.push_back(b.path);
  check_output_file(opt.output, inputs);
  StreamWriter out(opt.output,
                   scene.rebars.empty() ? kStreamMinorWithoutRebar : kStreamVersionMinor);
  out.write_text(RecordType::Scene, text);
  std::ostringstream info;
  info << "tool = \"mpm-prep\"\nversion = \"" << kVersion
       << "\"\nseconds = " << omp_get_wtime() - t0 << "\n";
  for (std::size_t b = 0; b < report.size(); ++b)
    info << "[[bodies]]\nname = \"" << report[b].name << "\"\nparticles = " << report[b].particles
         << "\nspacing = " << report[b].spacing << "\nmass = " << report[b].mass
         << "\nexact_mass = " << report[b].exact_mass << "\n";
  out.write_text(RecordType::Info, info.str());
  if (graded) out.write_record(RecordType::Grid, graded->grid_record);
  Frame frame;
  frame.flags = kFrameModel;
  frame.columns = std::move(cols);
  out.write_frame(frame);
  if (!scene.rebars.empty()) {
    Frame elements;
    elements.flags = kFrameModel;
    elements.columns = std::move(rebar);
    out.write_rebar(elements);
  }
  out.write_end(0, "model");
  out.close();
}

/// Voxelisation of every cell with progress lines on stderr once a body takes a while: every
/// 2 s after the first 2 s, so small models print none.
VoxeliseCells progress_cells(const Scene& scene) {
  VoxeliseCells cells;
  auto start = std::make_shared<double>(omp_get_wtime());
  auto last = std::make_shared<double>(*start);
  auto body = std::make_shared<std::size_t>(0);
  cells.progress = [&scene, start, last, body](std::size_t b, double done) {
    const double now = omp_get_wtime();
    if (b != *body) *body = b, *start = now, *last = now;
    if (now - *start < 2 || now - *last < 2) return;
    *last = now;
    std::fprintf(stderr, "mpm-prep: filling body '%s' with particles: %.0f%% (%.0f s)\n",
                 scene.bodies[b].name.c_str(), 100 * done, now - *start);
  };
  return cells;
}

}  // namespace

int prepare_model(const PrepOptions& opt) {
  const double t0 = omp_get_wtime();
  Scene scene = load_scene(opt.scene, opt.overrides);
  std::optional<TargetProposal> proposal;  // --target-error: the scene with the proposed cells
  if (opt.target_error > 0) {
    proposal = propose_for_target(scene, opt.target_error);
    scene = parse_scene(scene.toml, scene.source, scene.directory, proposal->overrides);
  }
  std::vector<std::string> warnings = scene.warnings;
  const BodyBoxes boxes = body_boxes(scene);
  check_mesh_sizes(scene, boxes, warnings);
  print_warnings(warnings);
  const double limit = opt.max_memory > 0 ? opt.max_memory : machine_memory();
  if (limit > 0) check_resources(scene, estimate_resources(scene, boxes), limit);
  const Lattice lattice = fit_lattice(scene, boxes.lo, boxes.hi);
  check_domain_cuts(scene, lattice, boxes);
  std::vector<BodyReport> report;
  std::optional<GradedModel> graded;  // scenes with grid levels (004, section 3.2)
  if (!scene.grid.levels.empty()) graded = prepare_graded(scene, lattice, report);
  ColumnStore cols =
      graded ? std::move(graded->columns) : voxelise(scene, lattice, report, progress_cells(scene));
  apply_initial_fields(scene, cols);  // spin, velocity and stress fields
  const std::vector<FaceOffset> faces = face_offsets(scene, lattice, cols);  // before rebar nodes
  std::vector<RebarReport> rebar_report;  // truss elements, nodes after the bodies' particles
  ColumnStore rebar = discretise_rebar(scene, lattice, boxes.lo, boxes.hi, cols, rebar_report);
  const GradedModel* graded_grid = graded ? &*graded : nullptr;
  const std::string text = with_explicit_domain(scene.toml, lattice);
  Estimates estimates = estimate_run(scene, lattice, cols, graded_grid);
  if (!rebar_report.empty()) rebar_time_step(scene, rebar_report, estimates);
  if (!opt.quiet) {
    print_grid(scene, lattice, graded_grid);
    const std::size_t total = print_bodies(scene, report, lattice, boxes);
    print_face_offsets(scene, faces);
    print_face_places(scene, face_places(scene, lattice, boxes));
    if (!rebar_report.empty()) print_rebar(scene, rebar_report);
    print_materials(scene, graded_grid ? graded_grid->h_min : lattice.h);
    print_estimates(scene, estimates, total);
    if (proposal) print_proposal(*proposal, double(total) * estimates.steps);
    for (const std::string& s : scene_needs(scene, lattice, cols, report))
      std::fprintf(stderr, "  %s\n", s.c_str());
  }
  warnings.clear();
  overlap_warnings(scene, report, warnings);
  print_warnings(warnings);
  write_model(opt, scene, text, report, graded_grid, std::move(cols), std::move(rebar), t0);
  return kExitOk;
}

}  // namespace mpm
