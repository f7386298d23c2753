#pragma once
/// mpm-prep on graded grids (004, section 3.2): builds the grid (which checks the level
/// boxes), then voxelises the bodies level by level: a point belongs to the finest level whose
/// box holds it, and the particle spacing is that level's cell size / particles_per_cell.
#include <cstddef>
#include <string>
#include <vector>

#include "mpm/core/columns.hpp"
#include "mpm/grid/lattice.hpp"
#include "mpm/prep/voxelise.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm {

/// A graded model: the particles (with the column "level"), the GRID record of the grid, and
/// figures for mpm-prep's summary.
struct GradedModel {
  ColumnStore columns;
  std::vector<std::byte> grid_record;  ///< GRID payload (encode_grid)
  std::vector<std::size_t> cells;      ///< leaf cells per level (index 1..levels)
  std::vector<std::size_t> particles;  ///< particles per level (index 1..levels)
  std::size_t nodes = 0, hanging_nodes = 0, transition_cells = 0;
  double h_min = 0;  ///< the finest cell size, m
};

/// Builds the grid and the particles of a scene with grid levels. Reports per body are summed
/// over the levels (spacing: that of level 1). Throws InputError for bad level boxes (naming
/// their keys) or a body without particles.
GradedModel prepare_graded(const Scene& scene, const Lattice& lattice,
                           std::vector<BodyReport>& report);

}  // namespace mpm
