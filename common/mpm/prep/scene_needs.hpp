#pragma once
/// Private to prep: what a scene models that it might not need, measured from the scene and
/// its particles, for mpm-prep's summary ("model only what the scene requires"): a 3D scene
/// symmetric about an axis that the axisymmetric model would hold with fewer particles; an
/// equation of state whose nonlinearity the impact cannot reach; a grid window mostly empty.
#include <string>
#include <vector>

#include "mpm/core/columns.hpp"
#include "mpm/grid/lattice.hpp"
#include "mpm/prep/voxelise.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm {

/// Lines for the summary, each a finding with the figure it rests on; none when the scene
/// needs what it models (or the test does not apply).
std::vector<std::string> scene_needs(const Scene& scene, const Lattice& lattice,
                                     const ColumnStore& cols,
                                     const std::vector<BodyReport>& report);

}  // namespace mpm
