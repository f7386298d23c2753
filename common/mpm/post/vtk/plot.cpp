// mpm-post residual --plot: a projectile's velocity against time as a PNG chart, drawn with
// VTK's charts off-screen (an X display as for render).
#include <vtkAxis.h>
#include <vtkChartXY.h>
#include <vtkContextScene.h>
#include <vtkContextView.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPlot.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "mpm/core/error.hpp"
#include "mpm/post/residual.hpp"
#include "mpm/post/vtk/vtk_files.hpp"
#include "mpm/post/vtk/vtk_output.hpp"
#include "mpm/post/vtk/x_display.hpp"

namespace mpm {

using namespace vtk_internal;

namespace {

/// A table of columns named `names`, `rows` rows of zeros.
vtkNew<vtkTable> make_table(const std::vector<const char*>& names, vtkIdType rows) {
  vtkNew<vtkTable> t;
  for (const char* n : names) {
    vtkNew<vtkDoubleArray> a;
    a->SetName(n);
    t->AddColumn(a);
  }
  t->SetNumberOfRows(rows);
  return t;
}

void add_line(vtkChartXY* chart, vtkTable* t, int column, const unsigned char rgb[3], int type,
              float width) {
  vtkPlot* p = chart->AddPlot(type);
  p->SetInputData(t, 0, column);
  p->SetColor(rgb[0], rgb[1], rgb[2], 255);
  p->SetWidth(width);
}

}  // namespace

void plot_residual_png(const ResidualResult& r, const std::string& path, int width, int height) {
  const char* display = std::getenv("DISPLAY");
  if (!display || !*display)
    throw InputError(
        "--plot", "no X display (DISPLAY is not set); run under xvfb-run or call ensure_display");
  XDisplay x_display(display);  // closed after the window is gone
  if (!x_display.ok())
    throw InputError("--plot", std::string("cannot open the X display '") + display + "'");

  // The history: speed and the component along the initial direction, against time in us.
  const auto n = vtkIdType(r.history.size());
  auto table = make_table({"time (us)", "speed |v|", "along the initial direction"}, n);
  for (vtkIdType i = 0; i < n; ++i) {
    const ResidualSample& s = r.history[std::size_t(i)];
    table->SetValue(i, 0, s.time * 1e6);
    table->SetValue(i, 1, s.v.norm());
    table->SetValue(i, 2, s.v_along);
  }
  auto exit = make_table({"time (us)", "tail left the target"}, r.exit ? 1 : 0);
  if (r.exit) {
    exit->SetValue(0, 0, r.exit->time * 1e6);
    exit->SetValue(0, 1, r.exit->v.norm());
  }

  vtkNew<vtkContextView> view;
  view->GetRenderer()->SetBackground(1, 1, 1);
  vtkRenderWindow* window = view->GetRenderWindow();
  if (x_display.get()) window->SetDisplayId(x_display.get());
  window->SetOffScreenRendering(1);
  window->SetMultiSamples(0);
  window->SetSize(width, height);
  vtkNew<vtkChartXY> chart;
  view->GetScene()->AddItem(chart);
  char title[256];
  std::snprintf(title, sizeof title, "'%s': %.4g m/s at the end (t = %.4g us)%s", r.body.c_str(),
                r.end().v.norm(), r.end().time * 1e6, r.exit ? "" : ", not through");
  std::string text = title;
  if (r.exit) {
    std::snprintf(title, sizeof title, ", %.4g m/s when its tail left the target (%.4g us)",
                  r.exit->v.norm(), r.exit->time * 1e6);
    text += title;
  }
  chart->SetTitle(text);
  chart->GetTitleProperties()->SetFontSize(18);
  chart->SetShowLegend(true);
  const unsigned char blue[3] = {31, 119, 180}, red[3] = {214, 39, 40}, black[3] = {0, 0, 0};
  add_line(chart, table, 1, blue, vtkChart::LINE, 2.5f);
  add_line(chart, table, 2, red, vtkChart::LINE, 1.5f);
  if (r.exit) add_line(chart, exit, 1, black, vtkChart::POINTS, 8.0f);
  chart->GetAxis(vtkAxis::BOTTOM)->SetTitle("time (us)");
  chart->GetAxis(vtkAxis::LEFT)->SetTitle("velocity (m/s)");
  [[maybe_unused]] const GraphicsStack graphics;
  view->Render();  // initialises the window's OpenGL context before the pixels are read
  write_png(window, path);
}

}  // namespace mpm
