// Off-screen pictures of frames: particles as shaded discs coloured by a field, a colour
// bar, a title, a scale bar and the view direction, through an orthographic camera fitted to
// the particles (the whole body of a quarter or half model, cut by a section when asked).
#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkExecutive.h>
#include <vtkFloatArray.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkPointData.h>
#include <vtkPointGaussianMapper.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkSmartPointer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkWindowToImageFilter.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <utility>

#include "mpm/core/error.hpp"
#include "mpm/post/vtk/frame_columns.hpp"
#include "mpm/post/vtk/render_fields.hpp"
#include "mpm/post/vtk/render_view.hpp"
#include "mpm/post/vtk/vtk_files.hpp"
#include "mpm/post/vtk/vtk_output.hpp"
#include "mpm/post/vtk/x_display.hpp"

namespace mpm {

using namespace vtk_internal;

namespace {

/// "y>0" style clip: keep particles with (axis - centroid) op offset.
struct Clip {
  int axis = -1;  ///< -1: no clip
  bool greater = true;
  double offset = 0;
};

Clip parse_clip(const std::string& text, int dim) {
  Clip c;
  std::string s;
  for (char ch : text)
    if (!std::isspace(static_cast<unsigned char>(ch))) s += ch;
  if (s.empty()) return c;
  const std::string help = "clip '" + text +
                           "': expected an axis, < or > and an offset from the centroid in m, "
                           "e.g. \"y>0\" (keeps the particles on the +y side of the centroid)";
  if (s.size() < 2 || (s[0] != 'x' && s[0] != 'y' && s[0] != 'z') || (s[1] != '<' && s[1] != '>'))
    throw InputError("render", help);
  c.axis = s[0] - 'x';
  c.greater = s[1] == '>';
  std::size_t pos = 2;
  if (pos < s.size() && s[pos] == '=') ++pos;
  if (pos < s.size()) {
    const std::string num = s.substr(pos);
    char* end = nullptr;
    c.offset = std::strtod(num.c_str(), &end);
    if (end == num.c_str()) throw InputError("render", help);
    std::string rest = end;
    if (rest == "m" || rest.empty()) {
    } else if (rest == "mm") {
      c.offset *= 1e-3;
    } else {
      throw InputError("render", help);
    }
  }
  if (c.axis >= dim)
    throw InputError("render", "clip '" + text + "': a " + std::to_string(dim) + "D frame has no " +
                                   s[0] + " axis");
  return c;
}

void check_view(const std::string& view) {
  if (view != "side" && view != "front" && view != "top" && view != "iso" && view != "symmetry")
    throw InputError("render",
                     "unknown view '" + view + "'; use side, front, top, iso or symmetry");
}

/// "12.3 us" style time.
std::string format_time(double t) {
  const double a = std::abs(t);
  const char* unit = "ns";
  double scale = 1e9;
  if (a >= 1)
    unit = "s", scale = 1;
  else if (a >= 1e-3)
    unit = "ms", scale = 1e3;
  else if (a >= 1e-6 || a == 0)
    unit = "us", scale = 1e6;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.4g %s", t * scale, unit);
  return buf;
}

/// Viridis (matplotlib, CC0), sampled every 16th of its 256 entries.
constexpr double kViridis[17][3] = {
    {0.267004, 0.004874, 0.329415}, {0.282327, 0.094955, 0.417331}, {0.278826, 0.175490, 0.483397},
    {0.258965, 0.251537, 0.524736}, {0.229739, 0.322361, 0.545706}, {0.199430, 0.387607, 0.554642},
    {0.172719, 0.448791, 0.557885}, {0.149039, 0.508051, 0.557250}, {0.127568, 0.566949, 0.550556},
    {0.120638, 0.625828, 0.533488}, {0.157851, 0.683765, 0.501686}, {0.246070, 0.738910, 0.452024},
    {0.369214, 0.788888, 0.382914}, {0.515992, 0.831158, 0.294279}, {0.678489, 0.863742, 0.189503},
    {0.845561, 0.887322, 0.099702}, {0.993248, 0.906157, 0.143936}};

vtkSmartPointer<vtkLookupTable> viridis_table(double lo, double hi) {
  auto lut = vtkSmartPointer<vtkLookupTable>::New();
  const int n = 256;
  lut->SetNumberOfTableValues(n);
  for (int i = 0; i < n; ++i) {
    // Sample k sits at entry 16 k (k <= 15), the last sample at entry 255.
    const int k = i >= 240 ? 15 : i / 16;
    const double frac = i >= 240 ? (i - 240) / 15.0 : (i % 16) / 16.0;
    double rgb[3];
    for (int c = 0; c < 3; ++c)
      rgb[c] = kViridis[k][c] + frac * (kViridis[k + 1][c] - kViridis[k][c]);
    lut->SetTableValue(i, rgb[0], rgb[1], rgb[2], 1.0);
  }
  lut->SetTableRange(lo, hi);
  lut->SetNanColor(0.6, 0.6, 0.6, 1.0);
  lut->SetUseBelowRangeColor(false);
  lut->SetUseAboveRangeColor(false);
  return lut;
}

/// Particle radius: 0.5 x the edge of the median particle's volume (2D: area per 1 m;
/// axisymmetric: m / (rho r), the mass being per radian).
double estimate_radius(const Frame& frame, int dim, bool axisymmetric,
                       const std::vector<std::uint32_t>& keep, const double bounds[6]) {
  const Column* m = frame.columns.find("m");
  const Column* rho = frame.columns.find("rho");
  const Column& x = frame.columns.at("x");
  if (m && rho && m->info().components == 1 && rho->info().components == 1) {
    const std::size_t n = frame.columns.size();
    const std::size_t samples = std::min<std::size_t>(n, 100001);
    std::vector<double> vol;
    vol.reserve(samples);
    auto get = [](const Column& c, std::size_t i) {
      return visit_scalar(c.info().type,
                          [&](auto tag) { return value_at<decltype(tag)>(c, i, 0); });
    };
    for (std::size_t s = 0; s < samples; ++s) {
      const std::size_t i = samples == n ? s : s * (n - 1) / (samples - 1);
      const double v =
          get(*m, i) / get(*rho, i) / (axisymmetric ? std::abs(position(x, i)[0]) : 1.0);
      if (std::isfinite(v) && v > 0) vol.push_back(v);
    }
    if (!vol.empty()) {
      auto mid = vol.begin() + vol.size() / 2;
      std::nth_element(vol.begin(), mid, vol.end());
      return 0.5 * (dim == 3 ? std::cbrt(*mid) : std::sqrt(*mid / 1.0));
    }
  }
  // No mass or density: the spacing of particles spread evenly over their bounding box.
  double vol = 1;
  int k = 0;
  for (int a = 0; a < dim; ++a)
    if (bounds[2 * a + 1] > bounds[2 * a]) vol *= bounds[2 * a + 1] - bounds[2 * a], ++k;
  if (k == 0 || keep.empty()) return 1e-3;
  return 0.5 * std::pow(vol / double(keep.size()), 1.0 / k);
}

/// Sphere impostor for vtkPointGaussianMapper: a disc of radius 1 (in splat units), shaded
/// as the front half of a ball lit from the viewer.
constexpr const char* kSphereSplat =
    "//VTK::Color::Impl\n"
    "float dist2 = dot(offsetVCVSOutput.xy, offsetVCVSOutput.xy);\n"
    "if (dist2 > 1.0) { discard; }\n"
    "float shade = 0.55 + 0.45 * sqrt(1.0 - dist2);\n"
    "ambientColor *= shade;\n"
    "diffuseColor *= shade;\n";

/// Checks the options that need no frame: view, size, colour range, point radius.
void check_picture_options(const RenderOptions& options) {
  check_view(options.view);
  if (options.width < 16 || options.height < 16 || options.width > 16384 || options.height > 16384)
    throw InputError("render", "picture size " + std::to_string(options.width) + "x" +
                                   std::to_string(options.height) + " is out of range (16..16384)");
  if (options.range_given && !(options.range_max > options.range_min))
    throw InputError("render", "the colour range must have max > min");
  if (options.point_radius < 0 || !std::isfinite(options.point_radius))
    throw InputError("render", "the point radius must be positive (or 0 for automatic)");
}

/// The particles kept by the clip (all without one); throws when it keeps none.
std::vector<std::uint32_t> kept_particles(const Column& x, std::size_t n, const Clip& clip,
                                          const std::string& clip_text) {
  std::vector<std::uint32_t> keep;
  if (clip.axis < 0) {
    keep.resize(n);
    for (std::size_t i = 0; i < n; ++i) keep[i] = std::uint32_t(i);
  } else {
    double centroid = 0;
    for (std::size_t i = 0; i < n; ++i) centroid += position(x, i)[clip.axis];
    centroid /= double(n);
    const double cut = centroid + clip.offset;
    for (std::size_t i = 0; i < n; ++i) {
      const double c = position(x, i)[clip.axis];
      if (clip.greater ? c > cut : c < cut) keep.push_back(std::uint32_t(i));
    }
    if (keep.empty()) throw InputError("render", "clip '" + clip_text + "' leaves no particles");
  }
  return keep;
}

/// Colour range: given, else the field's finite min..max over the frame.
std::pair<double, double> colour_range(const RenderOptions& options,
                                       const std::vector<float>& values) {
  double lo = options.range_min, hi = options.range_max;
  if (!options.range_given) {
    lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (float v : values)
      if (std::isfinite(v)) lo = std::min(lo, double(v)), hi = std::max(hi, double(v));
    if (!(lo <= hi)) lo = 0, hi = 1;
    if (hi - lo <= 1e-12 * std::max(std::abs(lo), std::abs(hi))) {
      const double pad = lo == 0 ? 1.0 : 0.01 * std::abs(lo);
      lo -= pad, hi += pad;
    }
  }
  return {lo, hi};
}

/// Poly data of the particles drawn: float positions and the field as scalars; `bounds` is
/// their bounding box.
vtkSmartPointer<vtkPolyData> particle_poly(const Drawn& drawn, const FieldValues& field,
                                           double bounds[6]) {
  const std::size_t np = drawn.size();
  vtkNew<vtkFloatArray> xyz;
  xyz->SetNumberOfComponents(3);
  xyz->SetNumberOfTuples(vtkIdType(np));
  vtkNew<vtkFloatArray> scalars;
  scalars->SetName(field.label.c_str());
  scalars->SetNumberOfTuples(vtkIdType(np));
  std::copy(drawn.xyz.begin(), drawn.xyz.end(), xyz->GetPointer(0));
  std::copy(drawn.values.begin(), drawn.values.end(), scalars->GetPointer(0));
  const float* pxyz = drawn.xyz.data();
  for (int a = 0; a < 3; ++a) {
    bounds[2 * a] = std::numeric_limits<double>::infinity();
    bounds[2 * a + 1] = -std::numeric_limits<double>::infinity();
  }
  for (std::size_t j = 0; j < np; ++j)
    for (int a = 0; a < 3; ++a)
      bounds[2 * a] = std::min(bounds[2 * a], double(pxyz[3 * j + a])),
                 bounds[2 * a + 1] = std::max(bounds[2 * a + 1], double(pxyz[3 * j + a]));
  vtkNew<vtkPoints> points;
  points->SetData(xyz);
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(points);
  poly->GetPointData()->SetScalars(scalars);
  return poly;
}

/// The particles as sphere impostors of `radius`, coloured through `lut` over lo..hi.
vtkSmartPointer<vtkPointGaussianMapper> particle_mapper(vtkPolyData* poly, vtkLookupTable* lut,
                                                        double lo, double hi, double radius) {
  auto mapper = vtkSmartPointer<vtkPointGaussianMapper>::New();
  mapper->SetInputData(poly);
  mapper->SetScaleFactor(radius);
  mapper->SetSplatShaderCode(kSphereSplat);
  mapper->SetTriangleScale(1.0f);  // the splat is a disc of radius 1 x scale
  mapper->EmissiveOff();
  mapper->SetLookupTable(lut);
  mapper->SetScalarRange(lo, hi);
  mapper->SetScalarModeToUsePointData();
  mapper->SetColorModeToMapScalars();
  mapper->ScalarVisibilityOn();
  return mapper;
}

constexpr double kDark[3] = {0.1, 0.1, 0.12};  ///< text colour

/// The colour bar right of the particles, titled with the field and its unit.
vtkSmartPointer<vtkScalarBarActor> colour_bar(vtkLookupTable* lut, const FieldValues& field,
                                              int h) {
  std::string bar_title = field.label;
  if (!field.unit.empty() && field.unit != "-" && field.unit != "1")
    bar_title += " (" + field.unit + ")";
  auto bar = vtkSmartPointer<vtkScalarBarActor>::New();
  bar->SetLookupTable(lut);
  bar->SetTitle(bar_title.c_str());
  bar->SetNumberOfLabels(6);
  bar->SetLabelFormat("%-.3g");
  bar->SetMaximumNumberOfColors(256);
  bar->UnconstrainedFontSizeOn();
  bar->SetVerticalTitleSeparation(std::max(4, h / 80));
  bar->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  bar->GetPositionCoordinate()->SetValue(0.855, 0.08);
  bar->SetWidth(0.13);
  bar->SetHeight(0.78);
  bar->SetBarRatio(0.3);
  for (vtkTextProperty* tp : {bar->GetTitleTextProperty(), bar->GetLabelTextProperty()}) {
    tp->SetColor(kDark[0], kDark[1], kDark[2]);
    tp->ShadowOff();
    tp->ItalicOff();
    tp->SetFontFamilyToArial();
  }
  bar->GetTitleTextProperty()->SetFontSize(std::max(10, h / 42));
  bar->GetTitleTextProperty()->BoldOn();
  bar->GetLabelTextProperty()->SetFontSize(std::max(9, h / 50));
  bar->GetLabelTextProperty()->BoldOff();
  return bar;
}

/// The title, centred at the top.
vtkSmartPointer<vtkTextActor> title_text(const std::string& title, int h) {
  auto text = vtkSmartPointer<vtkTextActor>::New();
  text->SetInput(title.c_str());
  text->SetTextScaleModeToNone();
  vtkTextProperty* tp = text->GetTextProperty();
  tp->SetFontSize(std::max(12, h / 28));
  tp->SetColor(kDark[0], kDark[1], kDark[2]);
  tp->SetJustificationToCentered();
  tp->SetVerticalJustificationToTop();
  tp->SetFontFamilyToArial();
  tp->BoldOn();
  tp->ShadowOff();
  text->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  text->GetPositionCoordinate()->SetValue(0.5, 0.975);
  return text;
}

/// Camera: parallel projection fitted to the particles' bounding box seen along `view`, with a
/// margin of one particle radius and 6 %: the whole body in frame. Returns the parallel scale
/// (m).
double fit_camera(vtkRenderer* scene, const ViewAxes& view, const double bounds[6], double radius,
                  const double scene_vp[4], int w, int h) {
  const auto& dir = view.dir;
  const double centre[3] = {0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]),
                            0.5 * (bounds[4] + bounds[5])};
  double diag = 0;
  for (int a = 0; a < 3; ++a)
    diag += (bounds[2 * a + 1] - bounds[2 * a]) * (bounds[2 * a + 1] - bounds[2 * a]);
  diag = std::sqrt(diag) + 4 * radius;
  vtkCamera* camera = scene->GetActiveCamera();
  camera->ParallelProjectionOn();
  camera->SetFocalPoint(centre);
  camera->SetPosition(centre[0] - dir[0] * 2 * diag, centre[1] - dir[1] * 2 * diag,
                      centre[2] - dir[2] * 2 * diag);
  camera->SetViewUp(view.up.data());
  scene->ResetCamera(bounds);  // sets the distance and clipping range around the bounds
  camera->SetFocalPoint(centre);
  // Half extents of the bounding box along the screen's right and up directions.
  const std::array<double, 3>& right = view.right;
  double true_up[3];
  camera->GetViewUp(true_up);
  double hw = 0, hh = 0;
  for (int corner = 0; corner < 8; ++corner) {
    double d[3];
    for (int a = 0; a < 3; ++a) d[a] = bounds[2 * a + ((corner >> a) & 1)] - centre[a];
    hw = std::max(hw, std::abs(d[0] * right[0] + d[1] * right[1] + d[2] * right[2]));
    hh = std::max(hh, std::abs(d[0] * true_up[0] + d[1] * true_up[1] + d[2] * true_up[2]));
  }
  hw += radius, hh += radius;
  const double aspect = (scene_vp[2] - scene_vp[0]) * w / ((scene_vp[3] - scene_vp[1]) * h);
  const double scale = 1.06 * std::max({hh, hw / aspect, 1e-12});
  camera->SetParallelScale(scale);
  return scale;
}

/// The picture's caption: the view direction, the section and the mirror images drawn.
std::string caption(const ViewAxes& view, const Section& section, const Drawn& drawn,
                    const Symmetry& symmetry) {
  std::string text = view.text;
  char buf[96];
  if (section.axis >= 0) {
    std::snprintf(buf, sizeof buf, ", section %c = %.4g mm (the %s side)", "xyz"[section.axis],
                  section.position * 1e3, drawn.keep_greater ? "+" : "-");
    text += buf;
  }
  if (!symmetry.planes.empty()) {
    text += symmetry.axisymmetric ? "; mirrored in " : "; whole body: mirror images in ";
    for (std::size_t p = 0; p < symmetry.planes.size(); ++p) {
      std::snprintf(buf, sizeof buf, "%s%c = %.4g mm", p ? ", " : "",
                    "xyz"[symmetry.planes[p].axis], symmetry.planes[p].position * 1e3);
      text += buf;
    }
  }
  return text;
}

}  // namespace

void render_png(const Frame& frame, int dim, const RenderOptions& options,
                const std::string& path) {
  // Everything about the input is checked before a window is opened.
  const Column& x = positions(frame, dim, "render");
  const std::size_t n = frame.columns.size();
  if (n == 0) throw InputError("render", "the frame has no particles");
  check_picture_options(options);
  FieldValues field = evaluate_field(frame, options.field, options.component);
  const Clip clip = parse_clip(options.clip, dim);
  const Section section = options.view == "symmetry" && dim == 3
                              ? symmetry_section(options.symmetry)
                              : parse_section(options.section, dim);
  const char* display = std::getenv("DISPLAY");
  if (!display || !*display)
    throw InputError(
        "render", "no X display (DISPLAY is not set); run under xvfb-run or call ensure_display");
  // Declared before the window so that it is closed after the window is gone.
  XDisplay x_display(display);
  if (!x_display.ok())
    throw InputError("render",
                     std::string("cannot open the X display '") + display +
                         "'; unset DISPLAY to render under xvfb-run, or start the X server");

  const std::vector<std::uint32_t> keep = kept_particles(x, n, clip, options.clip);
  const Drawn drawn = drawn_particles(x, keep, field, options.symmetry, section);
  const ViewAxes view = view_axes(options.view, dim, section, drawn.keep_greater);
  const auto [lo, hi] = colour_range(options, field.values);
  double bounds[6];
  auto poly = particle_poly(drawn, field, bounds);
  const double radius = options.point_radius > 0
                            ? options.point_radius
                            : estimate_radius(frame, dim, options.axisymmetric, keep, bounds);
  auto lut = viridis_table(lo, hi);
  auto mapper = particle_mapper(poly, lut, lo, hi, radius);
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  actor->GetProperty()->SetAmbient(0.0);
  actor->GetProperty()->SetDiffuse(1.0);

  // The particles fill a viewport left of the colour bar, below the title and above the scale
  // bar, drawn over a window-wide white renderer that holds the title, the colour bar and the
  // scale bar.
  const double scene_vp[4] = {0.0, 0.09, 0.84, 0.92};
  vtkNew<vtkRenderer> overlay;
  overlay->SetLayer(0);
  overlay->SetBackground(1, 1, 1);
  overlay->InteractiveOff();
  vtkNew<vtkRenderer> scene;
  scene->SetLayer(1);
  scene->SetViewport(scene_vp[0], scene_vp[1], scene_vp[2], scene_vp[3]);
  scene->SetBackground(1, 1, 1);
  scene->AddActor(actor);
  scene->LightFollowCameraOn();
  const int h = options.height, w = options.width;
  overlay->AddViewProp(colour_bar(lut, field, h));
  overlay->AddViewProp(title_text(
      options.title.empty() ? field.label + " at t = " + format_time(frame.time) : options.title,
      h));

  vtkNew<vtkRenderWindow> window;
  if (x_display.get()) window->SetDisplayId(x_display.get());
  window->SetOffScreenRendering(1);
  window->SetMultiSamples(0);
  window->SetNumberOfLayers(3);
  window->AddRenderer(scene);
  window->AddRenderer(overlay);
  vtkNew<vtkRenderer> bars;  // rebar over the particles: layer 2, the scene's camera
  if (!options.rebar.lines.empty()) {
    bars->SetLayer(2);
    bars->SetViewport(scene_vp[0], scene_vp[1], scene_vp[2], scene_vp[3]);
    bars->SetActiveCamera(scene->GetActiveCamera());
    bars->AddActor(rebar_actor(options.rebar, options.symmetry, section, drawn.keep_greater));
    bars->InteractiveOff();
    window->AddRenderer(bars);
  }
  window->SetSize(w, h);

  const double scale = fit_camera(scene, view, bounds, radius, scene_vp, w, h);
  add_scale_bar(overlay, scene_vp, w, h, scale, caption(view, section, drawn, options.symmetry));
  // Particles smaller than a pixel would fall between the pixel centres and vanish.
  const double pixel = 2 * scale / ((scene_vp[3] - scene_vp[1]) * h);
  mapper->SetScaleFactor(std::max(radius, 0.75 * pixel));
  scene->ResetCameraClippingRange(bounds[0] - radius, bounds[1] + radius, bounds[2] - radius,
                                  bounds[3] + radius, bounds[4] - radius, bounds[5] + radius);
  write_png(window, path);
}

}  // namespace mpm
