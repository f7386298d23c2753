#pragma once
/// ParaView output and off-screen pictures of frames (mpm-post vtk, mpm-post render).
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "mpm/core/types.hpp"
#include "mpm/post/symmetry.hpp"
#include "mpm/stream/stream.hpp"

namespace mpm {

struct GridMesh;        // stream/grid_record.hpp
struct ResidualResult;  // post/residual.hpp

/// Writes a frame as a VTK XML unstructured grid (.vtu) of vertex cells, one per particle,
/// with every column but "x" as point data of its own type (u8 -> vtkUnsignedCharArray,
/// u32 -> vtkUnsignedIntArray, ...): 2-component columns padded to 3 in 2D, 6-component
/// floating columns ("sigma") reordered from Voigt to VTK's tensor order xx, yy, zz, xy, yz, xz,
/// plus derived "pressure" (Pa, -tr(sigma)/3), "von_mises" (Pa) and "speed" (|v|) unless a
/// column has that name. Field data: "TIME" and "TimeValue" (s), "CYCLE" (step).
/// Binary, zlib-compressed appended data. Columns whose layout VTK shares are not copied.
/// `dim` is 2 or 3 (2D positions get z = 0). The file is written under a temporary name and
/// renamed. Throws IoError when the file cannot be written, InputError for a bad frame.
void write_vtu(const Frame& frame, int dim, const std::string& path);

/// Writes a graded grid (a GRID record) as a .vtu: its cells as hexahedra (quads in 2D) with
/// the cell fields "level" (1 = coarsest) and "optional_nodes" (how many mid-edge and mid-face
/// nodes a transition cell carries), the point field "hanging" (1 for a mid-edge or mid-face
/// node of a coarser cell), and field data "TIME", "TimeValue", "CYCLE". Written like
/// write_vtu (binary, zlib, under a temporary name). Throws IoError.
void write_grid_vtu(const GridMesh& mesh, const std::string& path);

/// The rebar of a frame: the elements of a REBR record between their node particles'
/// positions in the frame (elements whose nodes the frame lacks are left out).
struct RebarLines {
  std::vector<Vec3> points;                         ///< m, the node particles used
  std::vector<std::array<std::uint32_t, 2>> lines;  ///< points of each element
  std::vector<double> sigma, eps_p;                 ///< Pa, accumulated plastic strain
  std::vector<std::uint8_t> eroded;
};
RebarLines rebar_lines(const Frame& particles, const Frame& elements);

/// Writes rebar as a .vtu of line cells with the cell fields "axial_stress" (Pa),
/// "plastic_strain" and "eroded", and the field data of write_vtu. Throws IoError.
void write_rebar_vtu(const RebarLines& rebar, double time, std::int64_t step,
                     const std::string& path);

/// Writes a ParaView collection (.pvd) listing (time in s, file name relative to the .pvd).
/// Throws IoError when the file cannot be written.
void write_pvd(const std::vector<std::pair<double, std::string>>& entries, const std::string& path);

/// What a picture shows.
struct RenderOptions {
  std::string field = "eps_p";  ///< column or derived field ("pressure", "von_mises", "speed")
  int component = -1;           ///< for vectors/tensors: -1 magnitude, else that component
  int width = 1200, height = 900;
  std::string view = "side";  ///< "side" (looking along -y), "front" (-x), "top" (-z), "iso"
                              ///< (from +x+y+z), "symmetry" (square on to a mirror plane: the
                              ///< section there); 2D frames are always seen from +z
  bool range_given = false;   ///< else the range is the field's min..max in the frame
  double range_min = 0, range_max = 0;
  std::string title;        ///< drawn at the top; empty: field name and time
  double point_radius = 0;  ///< m; 0: estimated from particle mass and density
  std::string clip;  ///< "", "y>0" ...: keep particles on one side of a plane through the centroid
                     ///< ("y>0.002" or "y>2mm": a plane that far from the centroid)
  bool axisymmetric = false;  ///< 2D frame of an axisymmetric scene: a particle's mass is per
                              ///< radian, its area m / (rho r) (for the automatic radius)
  /// Mirror images drawn with each particle: the whole body of a quarter or half model; an
  /// axisymmetric frame's whole section through the axis (the plane x = 0). None: as it is.
  Symmetry symmetry;
  /// Rebar drawn over the particles as lines (eroded elements left out); empty: none.
  RebarLines rebar;
  /// "y = 0", "x = 2 mm": cut the body (with its images) at this plane, keep the side holding
  /// more particles and look square at the cut. Empty: no section.
  std::string section;
};

/// Renders a frame to a PNG off-screen, particles as spheres coloured by a field (viridis)
/// with a colour bar, orthographic camera fitted to what is drawn, a scale bar and the view
/// direction. Needs an X server (use ensure_display first).
/// Throws InputError for an unknown field (listing the available ones), bad options, or no
/// X display that can be opened; IoError when the PNG cannot be written.
void render_png(const Frame& frame, int dim, const RenderOptions& options, const std::string& path);

/// A chart of a projectile's velocity against time (mpm-post residual --plot): its speed and
/// the component along its initial direction, the exit marked, as a PNG of width x height
/// pixels. Needs an X server (ensure_display). Throws InputError when there is no display,
/// IoError when the PNG cannot be written.
void plot_residual_png(const ResidualResult& result, const std::string& path, int width = 1200,
                       int height = 800);

/// On a machine with no DISPLAY, re-runs this process (/proc/self/exe with argv[1..]) under
/// `xvfb-run -a` (once; guarded by MPM_UNDER_XVFB) so that VTK's off-screen rendering has an
/// X server; stdin, stdout and the exit status pass through. Call it before reading stdin.
/// Returns normally when a display is available; throws InputError when none is and xvfb-run
/// is missing, or when still none is under xvfb-run.
void ensure_display(int argc, char** argv);

}  // namespace mpm
