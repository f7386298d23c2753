#pragma once
/// Private to prep: what a model will need before any particle is made, so a scene whose
/// particles or grid cannot fit in memory (a cell size of 1 nm) is refused at once with the
/// estimate, instead of running out of memory.
#include <string>
#include <vector>

#include "mpm/prep/checks.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm {

/// Estimates from the bodies' boxes clipped to the domain and their exact volumes (meshes: their
/// boxes, an upper bound).
struct ResourceEstimate {
  std::vector<double> body_particles;  ///< particles of each body
  double particles = 0;                ///< all of them
  double prep_bytes = 0;      ///< mpm-prep: the voxeliser's bits and the model's columns, bytes
  double particle_bytes = 0;  ///< mpm-run: the particle columns, bytes
  double grid_bytes = 0;      ///< mpm-run: the grid window over the bodies at the start, bytes
  double run_bytes() const { return particle_bytes + grid_bytes; }
};

/// The estimate of a scene whose bodies' boxes are `boxes` (body_boxes).
ResourceEstimate estimate_resources(const Scene& scene, const BodyBoxes& boxes);

/// Throws InputError at grid.cell_size when mpm-prep or mpm-run would need more than `limit`
/// bytes, with the estimate, the limit and what to change.
void check_resources(const Scene& scene, const ResourceEstimate& estimate, double limit);

}  // namespace mpm
