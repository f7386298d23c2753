#pragma once
/// Bodies to particles (mpm-prep). Each body becomes n x n x n particles per cell (n x n in 2D)
/// at cell-aligned positions (cell corner + (i + 1/2) h / n) that lie inside the body, or, with
/// particle_spacing s, the points inside it of a lattice of spacing s centred on its bounding
/// box (round(L / s) points along each extent L), whatever the cells.
/// Primitives use exact inside tests (region.hpp); meshes (STL, OFF, OBJ) use CGAL's
/// Side_of_triangle_mesh on an AABB tree and must be closed (mesh_region.hpp).
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "mpm/core/columns.hpp"
#include "mpm/grid/lattice.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm {

/// What voxelisation produced for one body.
struct BodyReport {
  std::string name;
  std::size_t particles = 0;
  double mass = 0;                  ///< sum of particle masses, kg (per metre of thickness in 2D)
  double exact_mass = 0;            ///< density x exact volume, kg
  double spacing = 0;               ///< particle spacing (h / n, or particle_spacing), m
  double finest_spacing = 0;        ///< on a graded grid, that of the finest level it fills, m
  std::size_t skipped_overlap = 0;  ///< points inside an earlier body, not created again
};

/// Which cells of the lattice voxelise fills: one level of a graded grid (graded_voxelise.hpp).
struct VoxeliseCells {
  /// Keeps a cell (global index along x, y, z; z = 0 in 2D); empty: every cell.
  std::function<bool(const std::array<long long, 3>&)> keep;
  bool allow_empty = false;  ///< a body may get no particle in these cells
  /// Called as the first pass goes through a body (its index, the share of its rows done),
  /// about a hundred times a body, from the calling thread; empty: no progress.
  std::function<void(std::size_t, double)> progress;
};

/// Particles of all bodies, in body order. Columns: id (u32), body (u8), material (u8),
/// x (dim x f64, m), v (dim x f64, m/s), m (f64, kg), rho (f64, kg/m^3).
/// A point inside an earlier body is not created again (the earlier body owns it).
/// Throws InputError when a body gets no particle (naming the body and its scene line).
/// With `cells`, only the cells it keeps are filled (and, with allow_empty, a body may get none).
ColumnStore voxelise(const Scene& scene, const Lattice& lattice, std::vector<BodyReport>& report,
                     const VoxeliseCells& cells = {});

}  // namespace mpm
