#pragma once
/// ParaView output and off-screen pictures of frames (mpm-post vtk, mpm-post render).
#include <string>
#include <utility>
#include <vector>

#include "mpm/stream.hpp"

namespace mpm {

/// Writes a frame as a VTK XML unstructured grid (.vtu) of vertex cells, one per particle,
/// with every column as point data: vectors padded to 3 components in 2D, "sigma" as a
/// 6-component tensor (VTK order xx, yy, zz, xy, yz, xz) plus derived "pressure" (Pa,
/// -tr(sigma)/3) and "von_mises" (Pa). Binary, zlib-compressed appended data.
/// `dim` is 2 or 3 (2D positions get z = 0). Throws IoError when the file cannot be written.
void write_vtu(const Frame& frame, int dim, const std::string& path);

/// Writes a ParaView collection (.pvd) listing (time in s, file name relative to the .pvd).
void write_pvd(const std::vector<std::pair<double, std::string>>& entries, const std::string& path);

/// What a picture shows.
struct RenderOptions {
  std::string field = "eps_p";  ///< column or derived field ("pressure", "von_mises", "speed")
  int component = -1;           ///< for vectors/tensors: -1 magnitude, else that component
  int width = 1200, height = 900;
  std::string view = "side";    ///< "side" (looking along -y), "front" (-x), "top" (-z), "iso"
  bool range_given = false;     ///< else the range is the field's min..max in the frame
  double range_min = 0, range_max = 0;
  std::string title;            ///< drawn at the top; empty: field name and time
  double point_radius = 0;      ///< m; 0: estimated from particle mass and density
  std::string clip;             ///< "", "y>0" ...: keep particles on one side of a plane through the centroid
};

/// Renders a frame to a PNG off-screen, particles as spheres coloured by a field with a colour
/// bar. Needs an X server (use ensure_display first). Throws InputError for an unknown field.
void render_png(const Frame& frame, int dim, const RenderOptions& options, const std::string& path);

/// On a machine with no DISPLAY, re-runs this process under `xvfb-run -a` (once; guarded by an
/// environment variable) so that VTK's off-screen rendering has an X server. Returns normally
/// when a display is available; throws InputError when none is and xvfb-run is missing.
void ensure_display(int argc, char** argv);

}  // namespace mpm
