// Graded grids (GRID records) as ParaView files.
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnstructuredGrid.h>

#include <bit>
#include <vector>

#include "mpm/post/vtk/vtk_files.hpp"
#include "mpm/post/vtk/vtk_output.hpp"
#include "mpm/stream/grid_record.hpp"

namespace mpm {

void write_grid_vtu(const GridMesh& mesh, const std::string& path) {
  const std::size_t nn = mesh.nodes(), nc = mesh.cells();
  const int corners = 1 << mesh.dim;
  vtkNew<vtkUnstructuredGrid> grid;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(vtkIdType(nn));
  for (std::size_t n = 0; n < nn; ++n)
    points->SetPoint(vtkIdType(n), mesh.x[3 * n], mesh.x[3 * n + 1], mesh.x[3 * n + 2]);
  grid->SetPoints(points);
  // VTK's corner order from the grid's bit order (bit a set: upper along axis a).
  static constexpr int kHex[8] = {0, 1, 3, 2, 4, 5, 7, 6};
  vtkNew<vtkCellArray> cells;
  cells->AllocateExact(vtkIdType(nc), vtkIdType(nc * corners));
  std::vector<vtkIdType> ids(corners);
  for (std::size_t c = 0; c < nc; ++c) {
    for (int k = 0; k < corners; ++k) ids[k] = vtkIdType(mesh.corners[c * corners + kHex[k]]);
    cells->InsertNextCell(corners, ids.data());
  }
  grid->SetCells(mesh.dim == 3 ? VTK_HEXAHEDRON : VTK_QUAD, cells);
  vtkNew<vtkUnsignedCharArray> level, optional;
  level->SetName("level");
  optional->SetName("optional_nodes");
  level->SetNumberOfValues(vtkIdType(nc));
  optional->SetNumberOfValues(vtkIdType(nc));
  for (std::size_t c = 0; c < nc; ++c) {
    level->SetValue(vtkIdType(c), mesh.level[c]);
    optional->SetValue(vtkIdType(c), static_cast<unsigned char>(std::popcount(mesh.mask[c])));
  }
  grid->GetCellData()->AddArray(level);
  grid->GetCellData()->AddArray(optional);
  grid->GetCellData()->SetActiveScalars("level");
  vtkNew<vtkUnsignedCharArray> hanging;
  hanging->SetName("hanging");
  hanging->SetNumberOfValues(vtkIdType(nn));
  hanging->FillValue(0);
  for (auto n : mesh.optional) hanging->SetValue(vtkIdType(n), 1);
  grid->GetPointData()->AddArray(hanging);
  vtk_internal::write_unstructured(grid, mesh.time, mesh.step, path);
}

}  // namespace mpm
