#pragma once
/// The subcommands of mpm-post that need VTK: vtk (ParaView files) and render (PNG). Exit
/// statuses and errors as for the others (post/commands.hpp).
#include <string>

#include "mpm/post/vtk/vtk_output.hpp"

namespace mpm {

/// mpm-post vtk: a .vtu per frame and a .pvd series in a directory; graded grids (GRID
/// records) as <name>_grid_NNNN.vtu and <name>_grid.pvd.
struct VtkArgs {
  std::string input = "-";        ///< stream ("-": stdin)
  std::string directory = "vtk";  ///< created when missing
  std::string name = "frame";     ///< file name prefix
  int every = 1;                  ///< write every Nth frame (the final one always)
};
int post_vtk(const VtkArgs& args);

/// mpm-post render: a PNG picture of a frame, off-screen. Needs a display: call
/// ensure_display first.
struct RenderArgs {
  std::string input = "-";           ///< stream ("-": stdin)
  std::string output = "frame.png";  ///< PNG file
  std::string frame = "last";        ///< frame index (0 = first) or "last"
  std::string time;                  ///< the frame nearest this time; empty: by `frame`
  std::string size = "1200x900";     ///< WIDTHxHEIGHT in pixels
  std::string range;                 ///< colour range MIN:MAX (SI); empty: the field's
  bool half = false;                 ///< axisymmetric frames: the half plane r >= 0 only
  std::string symmetry;              ///< mirror planes (option_symmetry); empty: the scene's
  RenderOptions picture;             ///< field, component, view, clip, title, radius as given
};
int post_render(const RenderArgs& args);

}  // namespace mpm
