// Rebar (REBR records) as ParaView line cells, and its segments for pictures.
#include <vtkActor.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkSmartPointer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnstructuredGrid.h>

#include <unordered_map>

#include "mpm/core/error.hpp"
#include "mpm/post/vtk/render_view.hpp"
#include "mpm/post/vtk/vtk_files.hpp"
#include "mpm/post/vtk/vtk_output.hpp"
#include "mpm/scene/particles.hpp"
#include "mpm/scene/rebar_elements.hpp"

namespace mpm {

RebarLines rebar_lines(const Frame& particles, const Frame& elements) {
  RebarLines r;
  const Column* id = particles.columns.find(col::id);
  const Column* x = particles.columns.find(col::x);
  const Column* nodes = elements.columns.find(rebar_col::nodes);
  if (!id || !x || !nodes || id->info().type != ScalarType::U32 ||
      nodes->info().type != ScalarType::U32 || nodes->info().components != 2 ||
      x->info().type != ScalarType::F64)
    return r;  // a frame without ids or positions (output.fields), or not an element table
  const int dim = x->info().components;
  const auto* ids = id->as<std::uint32_t>();
  const auto* xs = reinterpret_cast<const double*>(x->data());
  const auto* ends = reinterpret_cast<const std::uint32_t*>(nodes->data());
  std::unordered_map<std::uint32_t, std::uint32_t> point_of;  // node id -> point
  constexpr std::uint32_t kAbsent = ~0u;
  for (std::size_t k = 0; k < 2 * elements.columns.size(); ++k) point_of.emplace(ends[k], kAbsent);
  for (std::size_t i = 0; i < particles.columns.size(); ++i) {
    auto it = point_of.find(ids[i]);
    if (it == point_of.end()) continue;
    it->second = std::uint32_t(r.points.size());
    Vec3 p = Vec3::Zero();
    for (int a = 0; a < dim; ++a) p[a] = xs[i * dim + a];
    r.points.push_back(p);
  }
  auto value = [&](const std::string& name, std::size_t e) {
    const Column* c = elements.columns.find(name);
    if (!c || c->info().components != 1) return 0.0;
    if (c->info().type == ScalarType::F64) return c->as<double>()[e];
    if (c->info().type == ScalarType::U8) return double(c->as<std::uint8_t>()[e]);
    return 0.0;
  };
  for (std::size_t e = 0; e < elements.columns.size(); ++e) {
    const auto a = point_of.find(ends[2 * e]), b = point_of.find(ends[2 * e + 1]);
    if (a->second == kAbsent || b->second == kAbsent) continue;  // a node not in the frame
    r.lines.push_back({a->second, b->second});
    r.sigma.push_back(value(rebar_col::sigma, e));
    r.eps_p.push_back(value(rebar_col::eps_pbar, e));
    r.eroded.push_back(std::uint8_t(value(rebar_col::eroded, e)));
  }
  return r;
}

void write_rebar_vtu(const RebarLines& r, double time, std::int64_t step, const std::string& path) {
  vtkNew<vtkUnstructuredGrid> grid;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(vtkIdType(r.points.size()));
  for (std::size_t k = 0; k < r.points.size(); ++k)
    points->SetPoint(vtkIdType(k), r.points[k].data());
  grid->SetPoints(points);
  vtkNew<vtkCellArray> cells;
  cells->AllocateExact(vtkIdType(r.lines.size()), vtkIdType(2 * r.lines.size()));
  for (const auto& l : r.lines) {
    const vtkIdType ids[2] = {vtkIdType(l[0]), vtkIdType(l[1])};
    cells->InsertNextCell(2, ids);
  }
  grid->SetCells(VTK_LINE, cells);
  vtkNew<vtkDoubleArray> sigma, eps_p;
  vtkNew<vtkUnsignedCharArray> eroded;
  sigma->SetName("axial_stress");
  eps_p->SetName("plastic_strain");
  eroded->SetName("eroded");
  const vtkIdType n = vtkIdType(r.lines.size());
  sigma->SetNumberOfValues(n), eps_p->SetNumberOfValues(n), eroded->SetNumberOfValues(n);
  for (vtkIdType e = 0; e < n; ++e) {
    sigma->SetValue(e, r.sigma[e]);
    eps_p->SetValue(e, r.eps_p[e]);
    eroded->SetValue(e, r.eroded[e]);
  }
  grid->GetCellData()->AddArray(sigma);
  grid->GetCellData()->AddArray(eps_p);
  grid->GetCellData()->AddArray(eroded);
  grid->GetCellData()->SetActiveScalars("axial_stress");
  vtk_internal::write_unstructured(grid, time, step, path);
}

}  // namespace mpm

namespace mpm::vtk_internal {

vtkSmartPointer<vtkActor> rebar_actor(const RebarLines& r, const Symmetry& symmetry,
                                      const Section& section, bool keep_greater) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  const int images = symmetry.images();
  for (int k = 0; k < images; ++k)  // image k of point j is point k n + j
    for (const Vec3& p : r.points) points->InsertNextPoint(symmetry.point_image(p, k).data());
  auto kept = [&](vtkIdType id) {  // on the side of the section the picture keeps
    if (section.axis < 0) return true;
    const double c = points->GetPoint(id)[section.axis];
    return keep_greater ? c >= section.position : c <= section.position;
  };
  vtkNew<vtkCellArray> lines;
  const vtkIdType n = vtkIdType(r.points.size());
  for (int k = 0; k < images; ++k)
    for (std::size_t e = 0; e < r.lines.size(); ++e) {
      if (r.eroded[e]) continue;  // removed: a gap in the bar
      const vtkIdType ids[2] = {k * n + vtkIdType(r.lines[e][0]), k * n + vtkIdType(r.lines[e][1])};
      if (kept(ids[0]) && kept(ids[1])) lines->InsertNextCell(2, ids);
    }
  vtkNew<vtkPolyData> poly;
  poly->SetPoints(points);
  poly->SetLines(lines);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(poly);
  mapper->ScalarVisibilityOff();
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(0.8, 0.1, 0.1);
  actor->GetProperty()->SetLineWidth(3);
  actor->GetProperty()->SetLighting(false);
  return actor;
}

}  // namespace mpm::vtk_internal
