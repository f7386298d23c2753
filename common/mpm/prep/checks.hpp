#pragma once
/// Private to prep: what mpm-prep checks of the bodies before it makes any particle, so a
/// scene that is valid but wrong (a mesh in millimetres read as metres, a body the domain cuts
/// off) stops with the key and the fix instead of giving a wrong model with exit status 0.
#include <string>
#include <vector>

#include "mpm/core/types.hpp"
#include "mpm/grid/lattice.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm {

/// The bodies' world bounding boxes (m; z = 0 in 2D), in scene order.
struct BodyBoxes {
  std::vector<Vec3> lo, hi;
};

/// The bounding boxes of the scene's bodies (mesh files are read, without their trees).
/// Throws InputError for a bad shape or mesh file, as make_region does.
BodyBoxes body_boxes(const Scene& scene);

/// Meshes whose size is implausible: mesh files carry no unit and are read in metres, so a
/// mesh drawn in millimetres is 1000 times too large. A mesh body more than 10 times the given
/// domain across is an error; more than 100 times the largest other body, or (alone) more than
/// 2 m across, a warning (appended to `warnings`). Both name the body, the file and the mesh's
/// size in m, and suggest `scale = 0.001`.
void check_mesh_sizes(const Scene& scene, const BodyBoxes& boxes,
                      std::vector<std::string>& warnings);

/// Bodies cut by the domain: a body that reaches beyond a face of the lattice by more than half
/// its particle spacing loses the part outside. That is an error naming the body, the face and
/// how far it reaches, unless the face is a symmetry plane (a "slip" face, or the axis of an
/// axisymmetric scene) or the body says the cut is meant (`cut_by_domain = true`).
void check_domain_cuts(const Scene& scene, const Lattice& lattice, const BodyBoxes& boxes);

}  // namespace mpm
