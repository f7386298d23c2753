// Level-by-level voxelisation of graded scenes (004, section 3.2, Fig. 7).
#include "mpm/prep/graded_voxelise.hpp"

#include <cmath>
#include <cstring>

#include "mpm/core/error.hpp"
#include "mpm/grid/graded_grid.hpp"
#include "mpm/prep/body_placement.hpp"
#include "mpm/scene/particles.hpp"

namespace mpm {

namespace {

template <int D>
GradedModel prepare(const Scene& scene, const Lattice& lattice, std::vector<BodyReport>& report) {
  const GradedGrid<D> grid(lattice, scene);  // checks the boxes
  GradedModel out;
  const int L = grid.levels();
  out.cells = grid.cells_per_level();
  out.particles.assign(L + 1, 0);
  out.nodes = grid.nodes();
  out.hanging_nodes = grid.hanging_nodes();
  out.transition_cells = grid.transition_cells();
  out.h_min = grid.min_cell_size();
  out.grid_record = encode_grid(grid.mesh(0, 0.0));

  // Level by level: the level's lattice, restricted to the cells no finer box covers.
  std::vector<ColumnStore> parts;
  report.clear();
  for (int l = 1; l <= L; ++l) {
    Lattice lat = lattice;
    lat.h = grid.level_h(l);
    for (int a = 0; a < D; ++a) lat.cells[a] = lattice.cells[a] << (l - 1);
    VoxeliseCells cells;
    cells.allow_empty = true;
    cells.keep = [&, l](const std::array<long long, 3>& c) {
      Vec<D> centre;
      for (int a = 0; a < D; ++a) centre[a] = lattice.origin[a] + (double(c[a]) + 0.5) * lat.h;
      return grid.level_at(centre) == l;
    };
    std::vector<BodyReport> rep;
    parts.push_back(voxelise(scene, lat, rep, cells));
    // A body's spacings: those of the coarsest and of the finest level it fills (voxelise
    // reports this level's; a level the body does not fill gives none).
    for (BodyReport& r : rep)
      if (r.particles == 0) r.spacing = r.finest_spacing = 0;
    out.particles[l] = parts.back().size();
    if (report.empty()) {
      report = rep;
    } else {
      for (std::size_t b = 0; b < rep.size(); ++b) {
        if (rep[b].particles > 0) {
          if (report[b].spacing == 0) report[b].spacing = rep[b].spacing;
          report[b].finest_spacing = rep[b].finest_spacing;
        }
        report[b].particles += rep[b].particles;
        report[b].mass += rep[b].mass;
        report[b].skipped_overlap += rep[b].skipped_overlap;
      }
    }
  }
  for (std::size_t b = 0; b < report.size(); ++b)
    if (report[b].particles == 0)
      throw InputError(body_where(scene, scene.bodies[b], ""),
                       "body '" + scene.bodies[b].name +
                           "' has no particles: it lies outside the domain, inside earlier "
                           "bodies, or is thinner than a particle spacing");

  // One store: the levels' particles one after the other, numbered again, with their level.
  std::size_t total = 0;
  for (const auto& p : parts) total += p.size();
  ColumnStore& cols = out.columns;
  for (const Column& c : parts.front().columns()) cols.add(c.info());
  cols.add({col::level, ScalarType::U8, 1, "-"});
  cols.resize(total);
  std::size_t at = 0;
  auto* level = cols.get<std::uint8_t>(col::level);
  for (int l = 1; l <= L; ++l) {
    const ColumnStore& p = parts[l - 1];
    for (const Column& c : p.columns()) {
      Column& dst = cols.at(c.info().name);
      if (c.bytes() > 0)
        std::memcpy(dst.data() + at * c.info().element_bytes(), c.data(), c.bytes());
    }
    std::fill(level + at, level + at + p.size(), std::uint8_t(l));
    at += p.size();
  }
  auto* id = cols.get<std::uint32_t>(col::id);
  for (std::size_t i = 0; i < total; ++i) id[i] = std::uint32_t(i);
  return out;
}

}  // namespace

GradedModel prepare_graded(const Scene& scene, const Lattice& lattice,
                           std::vector<BodyReport>& report) {
  if (scene.dimension == 3) return prepare<3>(scene, lattice, report);
  return prepare<2>(scene, lattice, report);
}

}  // namespace mpm
