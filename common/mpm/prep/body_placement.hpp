#pragma once
/// Private to prep: where a body is (its placement in the world, the path of its mesh file) and
/// where it is named in the scene, shared by the primitive regions (region.cpp), the mesh
/// regions (mesh_region.cpp) and the voxelisers.
#include <string>

#include "mpm/core/types.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm {

/// Rotation of a body: about x, then y, then z, by rotate_deg (degrees); R = Rz Ry Rx.
Mat3 body_rotation(const BodySpec& body);

/// The linear part of a body's placement, x_world = A x_local + translate, with A = R S
/// (scale applied first, then the rotation).
Mat3 body_linear_map(const BodySpec& body);

/// "bodies.<name>.<field>" located at the body's scene line, for InputError.
std::string body_where(const Scene& scene, const BodySpec& body, const std::string& field);

/// The mesh file of a body as a path to open: absolute paths as given, relative paths from
/// the scene's directory.
std::string resolve_mesh_path(const BodySpec& body, const Scene& scene);

}  // namespace mpm
