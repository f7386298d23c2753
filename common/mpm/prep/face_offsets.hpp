#pragma once
/// Private to prep: where the particles put a body's flat faces. Particles sit on a lattice of
/// their spacing s from the cell corners, so a flat face between two of its planes is filled
/// to the nearest one: the model's body ends up to s / 2 off the scene's (V5 at 6 / 3 mm cells
/// with the floor at -400 mm: the slab's struck face 1 mm low in level 1 and 0.5 mm proud in
/// level 2; examples/rc-slab/results.md, 2026-11-27). A face's place against the node planes can
/// matter as much, whether or not the particles fill it exactly (V5 at 434 m/s: 8% between its
/// struck face on a node plane and midway between two): face_places lists the faces inside a cell.
#include <string>
#include <vector>

#include "mpm/core/columns.hpp"
#include "mpm/grid/lattice.hpp"
#include "mpm/prep/checks.hpp"
#include "mpm/scene/scene.hpp"

namespace mpm {

/// A flat face of a body's bounding box and where its particles fill it to.
struct FaceOffset {
  std::size_t body = 0;
  int axis = 0;        ///< 0, 1, 2: x, y, z
  bool upper = false;  ///< the face at the box's maximum along axis (else its minimum)
  double face = 0;     ///< the scene's face, m
  double filled = 0;   ///< the particles' extent there (centre +- half their spacing), m
  double spacing = 0;  ///< the spacing of the particles that fill it (one level's), m
};

/// The flat faces of the primitive bodies (not meshes) that lie inside the domain and that
/// the particles fill to more than 1% of their spacing off the face, one entry for each
/// particle spacing that reaches the face (each level of a graded grid has its own lattice). A face
/// of the bounding box is flat when a quarter or more of a 16 x 16 sample of it, just inside, is in
/// the body (a box's faces, a cylinder's ends; not a sphere's or an ogive's tip). Bodies' spacing
/// from their particles' volume m / rho (2D: per metre; axisymmetric: per radian, m / (rho r)).
/// `cols` holds the bodies' particles only (before rebar nodes are appended: their "spacing" would
/// be their element's).
std::vector<FaceOffset> face_offsets(const Scene& scene, const Lattice& lattice,
                                     const ColumnStore& cols);

/// A flat face of a body's bounding box that lies inside the cells of a level it meets (not on
/// one of the level's node planes).
struct FacePlace {
  std::size_t body = 0;
  int axis = 0;      ///< 0, 1, 2: x, y, z
  double face = 0;   ///< the scene's face, m
  int level = 1;     ///< the grid level whose cells hold (part of) the face; 1: uniform grids
  double h = 0;      ///< that level's cell size, m
  double below = 0;  ///< the level's node plane just below the face along axis, m
};

/// The flat faces (as face_offsets finds them) of the primitive bodies that face something a
/// body can strike, and that lie more than 1% of a cell off the node planes of a level holding
/// part of them, one entry for each such level (the finest level at each of a 16 x 16 sample of
/// the face, just inside the body and the domain). A face faces another body whose bounding box
/// (`boxes`, body_boxes in checks.hpp) reaches beyond it and overlaps it across, or a domain
/// side beyond it that is a wall (slip or fixed). Node planes of level l lie at the domain's
/// corner plus whole multiples of cell_size / 2^(l - 1).
std::vector<FacePlace> face_places(const Scene& scene, const Lattice& lattice,
                                   const BodyBoxes& boxes);

/// The summary's line for one offset ("slab: face z = 0 mm filled to 0.5 mm (0.5 mm beyond
/// it; particles 1.5 mm apart)").
std::string describe(const Scene& scene, const FaceOffset& f);

/// The summary's line for one place ("slab: face z = 0 mm lies 2 mm above the node plane
/// z = -2 mm (0.5 of level 2's 4 mm cells)"; on a uniform grid "(0.3 of the 1 mm cells)").
std::string describe(const Scene& scene, const FacePlace& f);

}  // namespace mpm
