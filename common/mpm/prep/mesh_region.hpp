#pragma once
/// Private to prep (region.cpp, voxelise.cpp, mesh_region.cpp): the region of a triangle-mesh
/// body. CGAL stays inside mesh_region.cpp, which is the only translation unit that includes it
/// (it compiles slowly).
#include <cstddef>
#include <memory>

#include "mpm/core/types.hpp"
#include "mpm/prep/region.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm {

/// A closed triangle mesh placed in the world. The file is read with CGAL (STL ASCII or binary,
/// OFF, OBJ), repaired (duplicate vertices merged), oriented, triangulated, and checked: it must
/// have triangles, be closed, and not intersect itself. Inside tests cast rays through an AABB
/// tree built once in the constructor (CGAL::Side_of_triangle_mesh, exact predicates).
/// contains() and classify_box() only read the tree: they are safe from several threads.
class MeshRegion : public Region {
 public:
  /// Reads and checks the body's mesh. Throws InputError naming bodies.<name>.file, the scene
  /// line and the mesh file.
  MeshRegion(const BodySpec& body, const Scene& scene);
  ~MeshRegion() override;
  bool contains(const Vec3& x) const override;
  /// Volume enclosed by the placed mesh, m^3.
  double volume() const override;
  void bounds(Vec3& lo, Vec3& hi) const override;
  /// Where the closed box [lo, hi] (m) lies: 1 wholly inside, 0 wholly outside, -1 when the
  /// surface touches it (then test point by point).
  int classify_box(const Vec3& lo, const Vec3& hi) const;
  /// Number of triangles after triangulation.
  std::size_t triangles() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// World bounding box (m) of a mesh body's placed vertices, without the closedness checks or
/// the AABB tree (for fitting the lattice). Throws InputError when the file cannot be read or
/// has no triangles.
void mesh_body_bounds(const BodySpec& body, const Scene& scene, Vec3& lo, Vec3& hi);

}  // namespace mpm
