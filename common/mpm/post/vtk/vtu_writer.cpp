// ParaView files of frames: a .vtu per frame and the .pvd collection that lists them.
#include <vtkCellArray.h>
#include <vtkDoubleArray.h>
#include <vtkFloatArray.h>
#include <vtkIdTypeArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkSmartPointer.h>
#include <vtkTypeUInt64Array.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnsignedIntArray.h>
#include <vtkUnstructuredGrid.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <type_traits>

#include "mpm/core/error.hpp"
#include "mpm/post/vtk/frame_columns.hpp"
#include "mpm/post/vtk/vtk_files.hpp"
#include "mpm/post/vtk/vtk_output.hpp"

namespace mpm {

using namespace vtk_internal;

namespace {

/// The VTK array type holding scalars of type T.
template <class T>
vtkSmartPointer<vtkDataArray> new_vtk_array() {
  if constexpr (std::is_same_v<T, double>) return vtkSmartPointer<vtkDoubleArray>::New();
  if constexpr (std::is_same_v<T, float>) return vtkSmartPointer<vtkFloatArray>::New();
  if constexpr (std::is_same_v<T, std::uint8_t>)
    return vtkSmartPointer<vtkUnsignedCharArray>::New();
  if constexpr (std::is_same_v<T, std::uint32_t>)
    return vtkSmartPointer<vtkUnsignedIntArray>::New();
  if constexpr (std::is_same_v<T, std::int32_t>) return vtkSmartPointer<vtkIntArray>::New();
  if constexpr (std::is_same_v<T, std::uint64_t>) return vtkSmartPointer<vtkTypeUInt64Array>::New();
}

/// Point-data array of a column: shares the column's memory when the layouts agree, else a
/// padded (2D vectors to 3 components) or reordered (Voigt to VTK tensor order) copy.
vtkSmartPointer<vtkDataArray> column_array(const Column& col, int dim) {
  const ColumnInfo& info = col.info();
  const std::size_t n = col.size();
  return visit_scalar(info.type, [&](auto tag) -> vtkSmartPointer<vtkDataArray> {
    using T = decltype(tag);
    auto arr = new_vtk_array<T>();
    arr->SetName(info.name.c_str());
    auto* typed = static_cast<vtkAOSDataArrayTemplate<T>*>(arr.GetPointer());
    const T* src = raw<T>(col);
    const int nc = info.components;
    if (is_voigt(info)) {
      // Voigt xx, yy, zz, yz, xz, xy -> VTK symmetric tensor xx, yy, zz, xy, yz, xz.
      typed->SetNumberOfComponents(6);
      typed->SetNumberOfTuples(vtkIdType(n));
      T* dst = typed->GetPointer(0);
#pragma omp parallel for schedule(static)
      for (std::size_t i = 0; i < n; ++i) {
        const T* s = src + 6 * i;
        T* d = dst + 6 * i;
        d[0] = s[0], d[1] = s[1], d[2] = s[2], d[3] = s[5], d[4] = s[3], d[5] = s[4];
      }
    } else if (dim == 2 && nc == 2) {
      // A 2D vector: pad with z = 0 so ParaView treats it as a vector.
      typed->SetNumberOfComponents(3);
      typed->SetNumberOfTuples(vtkIdType(n));
      T* dst = typed->GetPointer(0);
#pragma omp parallel for schedule(static)
      for (std::size_t i = 0; i < n; ++i) {
        dst[3 * i] = src[2 * i];
        dst[3 * i + 1] = src[2 * i + 1];
        dst[3 * i + 2] = T(0);
      }
    } else {
      // Same layout: share the column's memory (save = 1: VTK never frees it).
      typed->SetNumberOfComponents(nc);
      if (n > 0) typed->SetArray(const_cast<T*>(src), vtkIdType(n) * nc, 1);
    }
    return arr;
  });
}

vtkSmartPointer<vtkDoubleArray> new_double_array(const char* name, int components, std::size_t n) {
  auto a = vtkSmartPointer<vtkDoubleArray>::New();
  a->SetName(name);
  a->SetNumberOfComponents(components);
  a->SetNumberOfTuples(vtkIdType(n));
  return a;
}

}  // namespace

void write_vtu(const Frame& frame, int dim, const std::string& path) {
  const Column& x = positions(frame, dim, "vtk");
  const std::size_t n = frame.columns.size();

  vtkNew<vtkUnstructuredGrid> grid;
  // Points: 3D f64 positions are shared, 2D ones padded with z = 0.
  vtkNew<vtkPoints> points;
  if (dim == 3 && x.info().type == ScalarType::F64) {
    vtkNew<vtkDoubleArray> xyz;
    xyz->SetNumberOfComponents(3);
    if (n > 0) xyz->SetArray(const_cast<double*>(raw<double>(x)), vtkIdType(3 * n), 1);
    points->SetData(xyz);
  } else {
    auto xyz = new_double_array("Points", 3, n);
    double* d = xyz->GetPointer(0);
#pragma omp parallel for schedule(static)
    for (std::size_t i = 0; i < n; ++i) {
      const auto p = position(x, i);
      d[3 * i] = p[0], d[3 * i + 1] = p[1], d[3 * i + 2] = p[2];
    }
    points->SetData(xyz);
  }
  grid->SetPoints(points);

  // One vertex per particle.
  vtkNew<vtkIdTypeArray> offsets, connectivity;
  offsets->SetNumberOfTuples(vtkIdType(n + 1));
  connectivity->SetNumberOfTuples(vtkIdType(n));
  vtkIdType* off = offsets->GetPointer(0);
  vtkIdType* con = connectivity->GetPointer(0);
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i <= n; ++i) {
    off[i] = vtkIdType(i);
    if (i < n) con[i] = vtkIdType(i);
  }
  vtkNew<vtkCellArray> cells;
  cells->SetData(offsets, connectivity);
  grid->SetCells(VTK_VERTEX, cells);

  // Every column but the positions, then the derived fields.
  vtkPointData* pd = grid->GetPointData();
  for (const Column& c : frame.columns.columns()) {
    if (c.info().name == "x") continue;
    pd->AddArray(column_array(c, dim));
  }
  const Column* sigma = frame.columns.find("sigma");
  if (sigma && is_voigt(sigma->info())) {
    const bool want_p = !frame.columns.has("pressure"), want_vm = !frame.columns.has("von_mises");
    auto p = new_double_array("pressure", 1, n);
    auto vm = new_double_array("von_mises", 1, n);
    double* pp = p->GetPointer(0);
    double* pv = vm->GetPointer(0);
#pragma omp parallel for schedule(static)
    for (std::size_t i = 0; i < n; ++i) {
      const Sym s = voigt_at(*sigma, i);
      pp[i] = -trace(s) / 3.0;
      pv[i] = von_mises(s);
    }
    if (want_p) pd->AddArray(p);
    if (want_vm) pd->AddArray(vm);
  }
  const Column* vel = frame.columns.find("v");
  if (vel && is_floating(vel->info().type) && !frame.columns.has("speed")) {
    auto sp = new_double_array("speed", 1, n);
    double* d = sp->GetPointer(0);
#pragma omp parallel for schedule(static)
    for (std::size_t i = 0; i < n; ++i) d[i] = norm_at(*vel, i);
    pd->AddArray(sp);
  }

  write_unstructured(grid, frame.time, frame.step, path);
}

void write_pvd(const std::vector<std::pair<double, std::string>>& entries,
               const std::string& path) {
  auto escape = [](const std::string& s) {
    std::string out;
    for (char c : s) {
      switch (c) {
        case '&':
          out += "&amp;";
          break;
        case '<':
          out += "&lt;";
          break;
        case '>':
          out += "&gt;";
          break;
        case '"':
          out += "&quot;";
          break;
        case '\'':
          out += "&apos;";
          break;
        default:
          out += c;
      }
    }
    return out;
  };
  std::ostringstream xml;
  xml << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "  <Collection>\n";
  char t[40];
  for (auto& [time, file] : entries) {
    std::snprintf(t, sizeof t, "%.17g", time);
    xml << "    <DataSet timestep=\"" << t << "\" group=\"\" part=\"0\" file=\"" << escape(file)
        << "\"/>\n";
  }
  xml << "  </Collection>\n</VTKFile>\n";
  const std::string text = xml.str();

  // Written next to the target and renamed, so a ParaView watching the file never sees half.
  FileTarget target(path);
  std::FILE* f = std::fopen(target.write_path().c_str(), "wb");
  if (!f) throw IoError("cannot write " + path + ": " + std::strerror(errno));
  const bool wrote = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  const int err = wrote ? 0 : errno;
  if (std::fclose(f) != 0 || !wrote)
    throw IoError("cannot write " + path + ": " + std::strerror(err ? err : errno));
  target.commit();
}

}  // namespace mpm
