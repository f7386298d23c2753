#pragma once
/// What a picture looks at (internal to mpm_vtk): the section plane, the camera's direction,
/// the particles drawn (the whole body of a quarter or half model: mirror images), and the
/// annotations that say so (a scale bar in a length unit, the view direction).
#include <vtkActor.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "mpm/post/symmetry.hpp"
#include "mpm/post/vtk/render_fields.hpp"
#include "mpm/post/vtk/vtk_output.hpp"
#include "mpm/stream/stream.hpp"

namespace mpm::vtk_internal {

struct Section;
/// Rebar as red lines, its eroded elements left out (rebar_writer.cpp), with its images in the
/// symmetry's planes and on the kept side of a section: drawn over the particles, in a layer
/// of its own, so that bars inside the material show.
vtkSmartPointer<vtkActor> rebar_actor(const RebarLines& rebar, const Symmetry& symmetry,
                                      const Section& section, bool keep_greater);

/// A section plane x_axis = position; the picture keeps one side and looks square at the cut.
struct Section {
  int axis = -1;        ///< -1: no section
  double position = 0;  ///< m
};

/// Parses "y = 0", "x = 2 mm", "z=-1.5mm" (plain numbers in m). Throws InputError naming
/// --section.
Section parse_section(const std::string& text, int dim);

/// The section of the view "symmetry": square on to a mirror plane of the model (y preferred,
/// then x, then z: the side view of a bar or impact along z). Throws InputError when the
/// model has none.
Section symmetry_section(const Symmetry& symmetry);

/// The camera: direction of projection, view-up and screen-right (unit vectors).
struct ViewAxes {
  std::array<double, 3> dir{0, 0, -1}, up{0, 1, 0}, right{1, 0, 0};
  std::string text;  ///< e.g. "seen along +y (x right, z up)"
};

/// The axes of a named view (side, front, top, iso; 2D: always from +z), or square on to the
/// cut of a section keeping the side `keep_greater`.
ViewAxes view_axes(const std::string& view, int dim, const Section& section, bool keep_greater);

/// The particles as drawn: float positions (3 per particle) and field values, each kept
/// particle and its mirror images, cut by the section.
struct Drawn {
  std::vector<float> xyz, values;
  bool keep_greater = true;  ///< the side of the section kept (the one with more particles)
  std::size_t size() const { return values.size(); }
};

/// Builds what is drawn from the frame's particles `keep` (after the clip), their images in the
/// symmetry's planes and the section. Throws InputError when the section leaves nothing.
Drawn drawn_particles(const Column& x, const std::vector<std::uint32_t>& keep,
                      const FieldValues& field, const Symmetry& symmetry, const Section& section);

/// Adds to `overlay` (a renderer over the whole w x h window), in the band below the
/// particles' viewport `vp` (seen by a parallel camera of `parallel_scale`, m), a scale bar of
/// a round length in a length unit that suits it (um, mm, m) and the line `caption` (view
/// direction, section, symmetry) right of it.
void add_scale_bar(vtkRenderer* overlay, const double vp[4], int w, int h, double parallel_scale,
                   const std::string& caption);

}  // namespace mpm::vtk_internal
