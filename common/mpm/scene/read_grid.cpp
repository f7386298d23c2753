// The scene parser's [grid] (domain, padding, sparse, [[grid.levels]]) and [boundary].
#include <cmath>
#include <string>
#include <string_view>

#include "mpm/core/error.hpp"
#include "mpm/core/units.hpp"
#include "mpm/scene/read_sections.hpp"

namespace mpm::scene_toml {

namespace {

/// [[grid.levels]]: the refined boxes of a graded grid (004, section 3.1). Alignment to the
/// coarser lattice and the domain are checked here; nesting and the one-level rule between
/// neighbouring cells when the grid is built (graded_grid.cpp), naming the same keys.
void read_levels(Reader& grid, Scene& s) {
  const toml::node* node = grid.get("levels");
  if (!node) return;
  const int n = s.dimension;
  const GridSpec& g = s.grid;
  const auto* arr = node->as_array();
  if (!arr)
    grid.fail(
        "levels",
        "expected an array of tables ([[grid.levels]], note the double brackets), " + got(*node));
  if (!g.domain_given)
    grid.fail("levels",
              "level boxes need grid.domain: they are aligned to the lattice that starts "
              "at domain.min");
  const Doc& doc = grid.doc();
  const Origin array_origin = grid.origin_of(*node);
  for (std::size_t i = 0; i < arr->size(); ++i) {
    const toml::node& e = (*arr)[i];
    const std::string path = "grid.levels." + std::to_string(i);
    const Origin o = doc.origin(e, array_origin);
    const auto* t = e.as_table();
    if (!t) throw InputError(doc.where(o, path), "expected a table ([[grid.levels]]), " + got(e));
    Reader r(doc, *t, path, o, {"level", "min", "max", "follow"});
    LevelSpec l;
    l.loc = r.loc();
    const auto level = r.integer("level", 2, 12);
    if (!level) r.missing("level", "2 for cells of half the grid.cell_size, 3 for a quarter, ...");
    l.level = int(*level);
    const std::string ex = n == 3 ? "\"-4 -4 0 mm\"" : "\"-4 0 mm\"";
    const auto lo = r.vector("min", dim::length, n);
    if (!lo) r.missing("min", "the box's lower corner, e.g. " + ex);
    const auto hi = r.vector("max", dim::length, n);
    if (!hi) r.missing("max", "the box's upper corner");
    l.min = *lo;
    l.max = *hi;
    const double hp = std::ldexp(g.cell_size, -(l.level - 2));  // the coarser level's cells
    for (int a = 0; a < n; ++a) {
      const std::string axis(1, "xyz"[a]);
      r.check("max", l.max[a] > l.min[a], "must exceed min in every component");
      for (const char* key : {"min", "max"}) {
        const double v = std::string_view(key) == "min" ? l.min[a] : l.max[a];
        if (v < g.domain_min[a] - 1e-9 * hp || v > g.domain_max[a] + 1e-9 * hp)
          r.fail(key, "the box leaves grid.domain along " + axis);
        const double cells = (v - g.domain_min[a]) / hp;
        if (std::abs(cells - std::round(cells)) > 1e-6)
          r.fail(key, "a level-" + std::to_string(l.level) + " box must lie on the level-" +
                          std::to_string(l.level - 1) + " lattice: " + axis + " = " +
                          format_number(v * 1e3) + " mm is not a multiple of " +
                          format_number(hp * 1e3) + " mm from grid.domain.min (nearest: " +
                          format_number((g.domain_min[a] + hp * std::round(cells)) * 1e3) + " mm)");
      }
    }
    if (const auto body = r.string("follow")) {
      l.follow = s.body_index(*body);
      if (l.follow < 0) {
        std::vector<std::string_view> known;
        for (const auto& b : s.bodies) known.push_back(b.name);
        r.fail("follow", "unknown body '" + *body + "' (known: " + join(known) + ")");
      }
    }
    r.finish();
    s.grid.levels.push_back(l);
  }
}

}  // namespace

void check_particle_spacing(const Scene& s) {
  const GridSpec& g = s.grid;
  for (const BodySpec& b : s.bodies) {
    if (b.particle_spacing <= 0) continue;
    const std::string at = where(b.spacing_loc.file, b.spacing_loc.line, b.spacing_loc.key);
    const auto mm = [](double v) { return format_mm(v) + " mm"; };
    if (!g.levels.empty())
      throw InputError(at,
                       "a graded grid ([[grid.levels]]) sets each level's spacing from its cells: "
                       "use particles_per_cell");
    // At least a particle per cell along each axis, and at most 16 (the voxeliser's limit).
    const std::string range = "expected a spacing from grid.cell_size / 16 to grid.cell_size (" +
                              mm(g.cell_size / 16) + " to " + mm(g.cell_size) + ")";
    if (b.particle_spacing > g.cell_size * (1 + 1e-9))
      throw InputError(at, range + ": coarser particles leave cells inside the body empty (got " +
                               mm(b.particle_spacing) + ")");
    if (b.particle_spacing < g.cell_size / 16 * (1 - 1e-9))
      throw InputError(at, range + ": finer particles than 16 per cell along an axis (got " +
                               mm(b.particle_spacing) + "; refine the cells instead)");
  }
}

void read_grid(Reader& r, Scene& s) {
  const int n = s.dimension;
  GridSpec& g = s.grid;
  g.loc = r.loc();
  g.cell_size = r.required("cell_size", dim::length, Bound::Positive, "0.76 mm");
  if (auto d = r.table("domain", {"min", "max"})) {
    const std::string ex_min = n == 3 ? "-10 -10 0 mm" : "-10 0 mm";
    const std::string ex_max = n == 3 ? "10 10 27 mm" : "10 27 mm";
    auto lo = d->vector("min", dim::length, n);
    if (!lo) d->missing("min", "the lower corner, e.g. \"" + ex_min + "\"");
    auto hi = d->vector("max", dim::length, n);
    if (!hi) d->missing("max", "the upper corner, e.g. \"" + ex_max + "\"");
    d->finish();
    for (int i = 0; i < n; ++i) {
      if (!((*hi)[i] > (*lo)[i])) {
        const std::string axis(1, "xyz"[i]);
        d->fail("max", "must be above min in every component, but " + axis + ": max " +
                           format_number((*hi)[i]) + " m <= min " + format_number((*lo)[i]) + " m");
      }
    }
    g.domain_given = true;
    g.domain_min = *lo;
    g.domain_max = *hi;
    if (r.get("padding")) {
      r.fail("padding",
             "cannot be combined with grid.domain (padding applies only when the domain is "
             "fitted to the bodies)");
    }
    g.padding = 0;
  } else {
    g.padding = r.quantity("padding", dim::length, Bound::NonNegative).value_or(2 * g.cell_size);
  }
  g.sparse = r.boolean("sparse").value_or(false);
  read_levels(r, s);
  if (g.sparse && !g.levels.empty())
    r.fail("sparse",
           "a graded grid ([[grid.levels]]) keeps its own node list; use one or the other");
  g.shape =
      r.choice<GridShape>("shape", {{"linear", GridShape::Linear}, {"bspline", GridShape::Bspline}})
          .value_or(GridShape::Linear);
  if (g.shape == GridShape::Bspline) {
    // What the quadratic B-spline grid has been built and tested for: a dense uniform grid,
    // 3D and plane strain or stress, without the kernels that still assume a cell's corners.
    const char* why = !g.levels.empty()     ? "a graded grid ([[grid.levels]])"
                      : g.sparse            ? "grid.sparse"
                      : s.axisymmetric      ? "axisymmetric scenes (the axis needs its own kernels)"
                      : !s.contacts.empty() ? "[[contact]] (the bodies' fields)"
                      : !s.rebars.empty()   ? "[[rebar]]"
                                            : nullptr;
    if (why)
      r.fail("shape", std::string("\"bspline\" runs on a dense uniform grid in 3D or plane "
                                  "strain/stress, not with ") +
                          why + "; use shape = \"linear\"");
  }
  r.finish();
}

void read_boundary(Reader& r, Scene& s) {
  static constexpr std::string_view kFaces[6] = {"x_min", "x_max", "y_min",
                                                 "y_max", "z_min", "z_max"};
  const auto read_type = [&r](std::string_view key) {
    return r.choice<BoundaryType>(key, {{"free", BoundaryType::Free},
                                        {"slip", BoundaryType::Slip},
                                        {"fixed", BoundaryType::Fixed}});
  };
  const BoundaryType all = read_type("all").value_or(BoundaryType::Free);
  for (int f = 0; f < 6; ++f) {
    if (s.dimension == 2 && f >= 4) {
      if (r.get(kFaces[f])) {
        r.fail(kFaces[f], "not available in 2D scenes (the faces are x_min, x_max, y_min, y_max)");
      }
      s.boundary.face[f] = BoundaryType::Free;
      continue;
    }
    s.boundary.face[f] = read_type(kFaces[f]).value_or(all);
  }
  r.finish();
}

}  // namespace mpm::scene_toml
