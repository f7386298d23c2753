// What a picture looks at: section, camera axes, the drawn particles, the scale bar.
#include "mpm/post/vtk/render_view.hpp"

#include <vtkActor2D.h>
#include <vtkCellArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper2D.h>
#include <vtkProperty2D.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <tuple>

#include "mpm/core/error.hpp"
#include "mpm/post/arguments.hpp"
#include "mpm/post/vtk/frame_columns.hpp"

namespace mpm::vtk_internal {

namespace {

constexpr double kInk[3] = {0.1, 0.1, 0.12};  ///< the annotations' colour

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

/// "+y", "-x", or the components of an oblique direction.
std::string axis_name(const std::array<double, 3>& d) {
  for (int a = 0; a < 3; ++a)
    if (std::abs(std::abs(d[a]) - 1) < 1e-12) return std::string(d[a] > 0 ? "+" : "-") + "xyz"[a];
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%.3g, %.3g, %.3g)", d[0], d[1], d[2]);
  return buf;
}

/// A length unit for a span of `span` m: um, mm or m, and its size in m.
std::pair<const char*, double> length_unit(double span) {
  if (span < 1e-3) return {"um", 1e-6};
  if (span < 1) return {"mm", 1e-3};
  return {"m", 1.0};
}

}  // namespace

Section parse_section(const std::string& text, int dim) {
  Section s;
  if (trim(text).empty()) return s;
  const std::size_t eq = text.find('=');
  const std::string axis = eq == std::string::npos ? "" : trim(text.substr(0, eq));
  if (axis != "x" && axis != "y" && axis != "z")
    throw InputError("--section",
                     "expected a plane such as \"x = 0\" or \"y = 2.5 mm\", got '" + text + "'");
  s.axis = axis[0] - 'x';
  if (s.axis >= dim)
    throw InputError("--section", "a " + std::to_string(dim) + "D frame has no " + axis +
                                      " axis: '" + text + "'");
  s.position = option_quantity(trim(text.substr(eq + 1)), dim::length, "--section");
  return s;
}

Section symmetry_section(const Symmetry& symmetry) {
  for (const int a : {1, 0, 2})
    for (const MirrorPlane& p : symmetry.planes)
      if (p.axis == a) return Section{p.axis, p.position};
  throw InputError("--view",
                   "the view 'symmetry' looks at the mirror planes of a quarter or half model, and "
                   "this model has none (no slip face through a body; --symmetry gives them): use "
                   "--section \"y = 0\" to cut the body anywhere");
}

ViewAxes view_axes(const std::string& view, int dim, const Section& section, bool keep_greater) {
  ViewAxes v;
  if (dim == 2) {  // the picture plane is the model plane whatever the view
    v.dir = {0, 0, -1}, v.up = {0, 1, 0};
  } else if (section.axis >= 0) {  // look along the normal, toward the side kept
    v.dir = {0, 0, 0};
    v.dir[section.axis] = keep_greater ? 1 : -1;
    v.up = section.axis == 2 ? std::array<double, 3>{0, 1, 0} : std::array<double, 3>{0, 0, 1};
  } else {
    const double r3 = 1.0 / std::sqrt(3.0);
    if (view == "side")
      v.dir = {0, -1, 0}, v.up = {0, 0, 1};
    else if (view == "front")
      v.dir = {-1, 0, 0}, v.up = {0, 0, 1};
    else if (view == "top")
      v.dir = {0, 0, -1}, v.up = {0, 1, 0};
    else
      v.dir = {-r3, -r3, -r3}, v.up = {0, 0, 1};
  }
  // Screen right = direction x up, made a unit vector (up need not be normal to dir: iso).
  const auto& d = v.dir;
  const auto& u = v.up;
  v.right = {d[1] * u[2] - d[2] * u[1], d[2] * u[0] - d[0] * u[2], d[0] * u[1] - d[1] * u[0]};
  const double n =
      std::sqrt(v.right[0] * v.right[0] + v.right[1] * v.right[1] + v.right[2] * v.right[2]);
  for (double& c : v.right) c /= n;
  v.text = "seen along " + axis_name(v.dir) + " (" + axis_name(v.right) + " right, " +
           axis_name(v.up) + " up)";
  return v;
}

Drawn drawn_particles(const Column& x, const std::vector<std::uint32_t>& keep,
                      const FieldValues& field, const Symmetry& symmetry, const Section& section) {
  Drawn d;
  const int images = symmetry.images();
  d.xyz.reserve(3 * keep.size() * std::size_t(images));
  d.values.reserve(keep.size() * std::size_t(images));
  // The side kept: the one with more of the whole body (ties: the greater side).
  std::size_t above = 0, below = 0;
  if (section.axis >= 0)
    for (const std::uint32_t i : keep) {
      const auto p = position(x, i);
      for (int k = 0; k < images; ++k) {
        const double c = symmetry.point_image(Vec3(p[0], p[1], p[2]), k)[section.axis];
        above += c >= section.position, below += c < section.position;
      }
    }
  d.keep_greater = above >= below;
  for (const std::uint32_t i : keep) {
    const auto p = position(x, i);
    for (int k = 0; k < images; ++k) {
      const Vec3 q = symmetry.point_image(Vec3(p[0], p[1], p[2]), k);
      if (section.axis >= 0 && (d.keep_greater ? q[section.axis] < section.position
                                               : q[section.axis] > section.position))
        continue;
      d.xyz.insert(d.xyz.end(), {float(q[0]), float(q[1]), float(q[2])});
      d.values.push_back(field.values[i]);
    }
  }
  if (d.values.empty()) throw InputError("--section", "the section leaves no particles");
  return d;
}

void add_scale_bar(vtkRenderer* overlay, const double vp[4], int w, int h, double parallel_scale,
                   const std::string& caption) {
  // Pixels per metre of the parallel camera: the viewport's height spans 2 parallel_scale.
  const double vp_w = (vp[2] - vp[0]) * w, vp_h = (vp[3] - vp[1]) * h;
  const double ppm = vp_h / (2 * parallel_scale);
  // A round length (1, 2 or 5 times a power of ten) of at most a fifth of the picture's width.
  const double most = 0.2 * vp_w / ppm;
  const auto [unit, size] = length_unit(5 * most);
  const double decade = std::pow(10.0, std::floor(std::log10(most / size)));
  double length = decade;
  for (const double f : {2.0, 5.0})
    if (f * decade <= most / size) length = f * decade;
  const double px = length * size * ppm;
  // In the band below the particles' viewport: the bar with end ticks at the left, its length
  // above it, the caption right of it.
  const double band = vp[1] * h;
  const double x0 = vp[0] * w + 0.03 * vp_w, y0 = 0.3 * band;
  const double tick = std::max(3.0, 0.12 * band);
  vtkNew<vtkPoints> pts;
  pts->InsertNextPoint(x0, y0, 0);
  pts->InsertNextPoint(x0 + px, y0, 0);
  pts->InsertNextPoint(x0, y0, 0);
  pts->InsertNextPoint(x0, y0 + tick, 0);
  pts->InsertNextPoint(x0 + px, y0, 0);
  pts->InsertNextPoint(x0 + px, y0 + tick, 0);
  vtkNew<vtkCellArray> lines;
  for (const vtkIdType a : {0, 2, 4}) {
    const vtkIdType seg[2] = {a, a + 1};
    lines->InsertNextCell(2, seg);
  }
  vtkNew<vtkPolyData> poly;
  poly->SetPoints(pts);
  poly->SetLines(lines);
  vtkNew<vtkPolyDataMapper2D> mapper;
  mapper->SetInputData(poly);
  vtkNew<vtkActor2D> bar;
  bar->SetMapper(mapper);
  bar->GetProperty()->SetColor(kInk[0], kInk[1], kInk[2]);
  bar->GetProperty()->SetLineWidth(float(std::max(2.0, h / 300.0)));
  overlay->AddViewProp(bar);
  const int font = std::max(9, int(0.24 * band));
  char label[64];
  std::snprintf(label, sizeof label, "%g %s", length, unit);
  // The caption in two lines when it has two parts ("view; section" and the mirror images).
  const std::size_t cut = caption.rfind("; ");
  const std::string line1 = cut == std::string::npos ? caption : caption.substr(0, cut);
  const std::string line2 = cut == std::string::npos ? "" : caption.substr(cut + 2);
  const double caption_x = x0 + std::max(px, 4.0 * font) + 0.03 * vp_w;
  using Text = std::tuple<std::string, double, double>;
  for (const auto& [text, x, y] : {Text{label, x0, y0 + 0.3 * band},
                                   Text{line1, caption_x, line2.empty() ? y0 : y0 + 0.35 * band},
                                   Text{line2, caption_x, y0 - 0.05 * band}}) {
    if (text.empty()) continue;
    vtkNew<vtkTextActor> t;
    t->SetInput(text.c_str());
    t->SetTextScaleModeToNone();
    vtkTextProperty* tp = t->GetTextProperty();
    tp->SetFontSize(font);
    tp->SetColor(kInk[0], kInk[1], kInk[2]);
    tp->SetFontFamilyToArial();
    tp->ShadowOff();
    t->SetDisplayPosition(int(x), int(y));
    overlay->AddViewProp(t);
  }
}

}  // namespace mpm::vtk_internal
