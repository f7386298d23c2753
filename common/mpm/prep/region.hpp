#pragma once
/// A body's region in world coordinates (after scale, rotation, translation): the exact
/// primitives, or a closed mesh (mesh_region.hpp), and the lattice of a scene fitted around
/// its bodies' regions.
#include <memory>
#include <vector>

#include "mpm/core/types.hpp"
#include "mpm/grid/lattice.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm {

/// A body's region in world coordinates (after scale, rotation, translation).
class Region {
 public:
  virtual ~Region() = default;
  /// True when x (m) is inside (points exactly on the surface may go either way).
  virtual bool contains(const Vec3& x) const = 0;
  /// Exact volume (m^3; in 2D the area in m^2): analytic for primitives, the closed mesh's
  /// signed volume for meshes.
  virtual double volume() const = 0;
  /// Axisymmetric 2D scenes: the volume per radian of the solid of revolution about the y
  /// axis swept by the part of the region at x >= 0, the integral of x over that part (m^3).
  /// Exact for the 2D primitives (rectangles, disks and their rotated, scaled images).
  virtual double revolved_volume() const;
  /// World-space bounding box.
  virtual void bounds(Vec3& lo, Vec3& hi) const = 0;
};

/// The region of a body. Reads and checks the mesh file for meshes.
/// Throws InputError naming the body's scene key and the file when the mesh cannot be read,
/// is empty, or is not closed.
std::unique_ptr<Region> make_region(const BodySpec& body, const Scene& scene);

/// The lattice of a scene for mpm-prep: its grid.domain when given (make_lattice), else the
/// bounding box of its bodies' regions (mesh files are read) plus grid.padding, with the maximum
/// corner rounded up to whole cells. Throws InputError as make_lattice does, when the padding is
/// bad or there is no body, and for a body whose shape, placement or mesh file is bad.
Lattice fit_lattice(const Scene& scene);
/// fit_lattice around the bodies' bounding boxes [body_lo[b], body_hi[b]] (m) already known.
Lattice fit_lattice(const Scene& scene, const std::vector<Vec3>& body_lo,
                    const std::vector<Vec3>& body_hi);

/// World bounding box of a body (m): reads mesh files but does not build their trees. Throws
/// InputError for a bad shape or mesh file.
void body_bounds(const BodySpec& body, const Scene& scene, Vec3& lo, Vec3& hi);

}  // namespace mpm
