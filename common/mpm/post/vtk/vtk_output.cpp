// ParaView output (.vtu, .pvd) and off-screen pictures of frames.
#include "mpm/post/vtk/vtk_output.hpp"

#include <dlfcn.h>
#include <unistd.h>
#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCommand.h>
#include <vtkDoubleArray.h>
#include <vtkErrorCode.h>
#include <vtkExecutive.h>
#include <vtkFieldData.h>
#include <vtkFloatArray.h>
#include <vtkIdTypeArray.h>
#include <vtkIntArray.h>
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
#include <vtkTypeInt64Array.h>
#include <vtkTypeUInt64Array.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnsignedIntArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkWindowToImageFilter.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <type_traits>

#include "mpm/core/error.hpp"
#include "mpm/core/types.hpp"
#include "mpm/stream/grid_record.hpp"

namespace mpm {
namespace {

// ---------------------------------------------------------------------------------------------
// Helpers shared by the writers and the renderer.

/// Collects the first error a VTK object reports instead of letting VTK print it.
class ErrorCatcher : public vtkCommand {
 public:
  static ErrorCatcher* New() { return new ErrorCatcher; }
  void Execute(vtkObject*, unsigned long event, void* data) override {
    if (event == vtkCommand::ErrorEvent && message.empty())
      message = data ? static_cast<const char*>(data) : "unknown VTK error";
  }
  std::string message;
};

/// Trims VTK's "ERROR: In file.cxx, line N\nvtkClass (0x...): text" to its last line.
std::string vtk_message(const std::string& m) {
  std::string s = m;
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  const auto nl = s.rfind('\n');
  if (nl != std::string::npos) s = s.substr(nl + 1);
  const auto colon = s.find("): ");
  if (colon != std::string::npos) s = s.substr(colon + 3);
  return s;
}

/// Why a VTK writer failed: its own error message, else its error code, else the pipeline's.
std::string writer_failure(const ErrorCatcher& own, unsigned long code,
                           const ErrorCatcher& pipeline, const std::string& written,
                           const std::string& path) {
  if (code > 0 && code < vtkErrorCode::FirstVTKErrorCode)  // a system errno
    return std::strerror(int(code));
  if (!own.message.empty()) {
    std::string m = vtk_message(own.message);
    for (auto at = m.find(written); !written.empty() && at != std::string::npos;
         at = m.find(written))
      m.replace(at, written.size(), path);
    return m;
  }
  switch (code) {
    case vtkErrorCode::OutOfDiskSpaceError:
      return "out of disk space";
    case vtkErrorCode::CannotOpenFileError:
      return "cannot open the file";
    case vtkErrorCode::NoFileNameError:
      return "no file name";
    case vtkErrorCode::NoError:
      break;
    default:
      return "VTK error code " + std::to_string(code);
  }
  if (!pipeline.message.empty()) return "the VTK pipeline failed";
  return "the VTK writer failed";
}

/// A file written under a temporary name next to its target and renamed over it once
/// complete, so that a failed write leaves neither half a file nor a damaged old one.
/// Targets that exist and are not regular files (devices, pipes, symbolic links) are
/// written in place and never removed.
class FileTarget {
 public:
  explicit FileTarget(std::string path) : path_(std::move(path)) {
    std::error_code ec;
    if (std::filesystem::is_directory(path_, ec))  // VTK's writers spin on a directory
      throw InputError(path_, "is a directory; expected the name of a file to write");
    const auto st = std::filesystem::symlink_status(path_, ec);
    const bool special =
        !ec && std::filesystem::exists(st) && !std::filesystem::is_regular_file(st);
    write_path_ = special ? path_ : path_ + ".tmp" + std::to_string(::getpid());
  }
  ~FileTarget() {
    if (!committed_ && write_path_ != path_) {
      std::error_code ec;
      std::filesystem::remove(write_path_, ec);
    }
  }
  FileTarget(const FileTarget&) = delete;
  FileTarget& operator=(const FileTarget&) = delete;
  /// The name to write to.
  const std::string& write_path() const { return write_path_; }
  /// Renames the finished file over the target; throws IoError.
  void commit() {
    if (write_path_ != path_ && std::rename(write_path_.c_str(), path_.c_str()) != 0)
      throw IoError("cannot write " + path_ + ": " + std::strerror(errno));
    committed_ = true;
  }

 private:
  std::string path_, write_path_;
  bool committed_ = false;
};

/// Calls f(T{}) with the C++ type of a scalar type.
template <class F>
decltype(auto) visit_scalar(ScalarType t, F&& f) {
  switch (t) {
    case ScalarType::F64:
      return f(double{});
    case ScalarType::F32:
      return f(float{});
    case ScalarType::U8:
      return f(std::uint8_t{});
    case ScalarType::U32:
      return f(std::uint32_t{});
    case ScalarType::I32:
      return f(std::int32_t{});
    case ScalarType::U64:
      return f(std::uint64_t{});
  }
  throw std::logic_error("unknown scalar type");
}

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

bool is_floating(ScalarType t) {
  return t == ScalarType::F64 || t == ScalarType::F32;
}

/// A 6-component floating column is a symmetric tensor in Voigt order (types.hpp: Sym).
bool is_voigt(const ColumnInfo& info) {
  return info.components == 6 && is_floating(info.type);
}

/// Element i, component c of a column as a double.
template <class T>
double value_at(const Column& c, std::size_t i, int k) {
  return double(reinterpret_cast<const T*>(c.data())[i * c.info().components + k]);
}

/// A column's data as a flat array of T (checked by type, not by element size).
template <class T>
const T* raw(const Column& c) {
  return reinterpret_cast<const T*>(c.data());
}

/// Voigt (xx, yy, zz, yz, xz, xy) of element i of a floating 6-component column.
Sym voigt_at(const Column& c, std::size_t i) {
  Sym s;
  if (c.info().type == ScalarType::F64) {
    const double* p = raw<double>(c) + 6 * i;
    for (int k = 0; k < 6; ++k) s[k] = p[k];
  } else {
    const float* p = raw<float>(c) + 6 * i;
    for (int k = 0; k < 6; ++k) s[k] = p[k];
  }
  return s;
}

/// Position of particle i padded to 3D.
std::array<double, 3> position(const Column& x, std::size_t i) {
  std::array<double, 3> p{0, 0, 0};
  const int nc = std::min(x.info().components, 3);
  for (int k = 0; k < nc; ++k)
    p[k] = x.info().type == ScalarType::F64 ? value_at<double>(x, i, k) : value_at<float>(x, i, k);
  return p;
}

const Column& positions(const Frame& frame, int dim, const char* where) {
  if (dim != 2 && dim != 3)
    throw InputError(where, "dimension must be 2 or 3, not " + std::to_string(dim));
  const Column* x = frame.columns.find("x");
  if (!x) throw InputError(where, "the frame has no position column 'x'");
  if (x->info().components != dim || !is_floating(x->info().type))
    throw InputError(where, "column 'x' has " + std::to_string(x->info().components) + " x " +
                                scalar_name(x->info().type) + ", expected " + std::to_string(dim) +
                                " x f64 for a " + std::to_string(dim) + "D frame");
  return *x;
}

// ---------------------------------------------------------------------------------------------
// .vtu

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

/// Adds a one-value field-data array.
template <class A, class V>
void add_field_value(vtkFieldData* fd, const char* name, V value) {
  vtkNew<A> a;
  a->SetName(name);
  a->SetNumberOfTuples(1);
  a->SetValue(0, value);
  fd->AddArray(a);
}

// ---------------------------------------------------------------------------------------------
// Fields for pictures.

/// Units of the usual columns when the column does not say.
std::string default_unit(const std::string& name) {
  static const std::pair<const char*, const char*> units[] = {
      {"x", "m"},    {"v", "m/s"}, {"m", "kg"},        {"rho", "kg/m^3"},   {"sigma", "Pa"},
      {"e", "J/kg"}, {"T", "K"},   {"pressure", "Pa"}, {"von_mises", "Pa"}, {"speed", "m/s"}};
  for (auto& [n, u] : units)
    if (name == n) return u;
  return "";
}

std::string unit_of(const ColumnInfo& info) {
  return info.unit.empty() ? default_unit(info.name) : info.unit;
}

/// A field evaluated on every particle.
struct FieldValues {
  std::string label;  ///< "pressure", "v_x", "|v|", ...
  std::string unit;   ///< "Pa", "" when none or dimensionless
  std::vector<float> values;
};

std::vector<std::string> available_fields(const Frame& frame) {
  std::vector<std::string> names;
  for (auto& c : frame.columns.columns()) names.push_back(c.info().name);
  auto add = [&](const char* n) {
    if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
  };
  const Column* sigma = frame.columns.find("sigma");
  if (sigma && is_voigt(sigma->info())) add("pressure"), add("von_mises");
  if (frame.columns.has("v")) add("speed");
  return names;
}

[[noreturn]] void unknown_field(const Frame& frame, const std::string& field) {
  std::string list;
  for (auto& n : available_fields(frame)) list += (list.empty() ? "" : ", ") + n;
  throw InputError("render", "unknown field '" + field + "'; available fields: " + list);
}

/// Evaluates `field` (component -1: magnitude, von Mises for tensors) on every particle.
FieldValues evaluate_field(const Frame& frame, const std::string& field, int component) {
  const std::size_t n = frame.columns.size();
  FieldValues out;
  out.values.resize(n);
  float* v = out.values.data();
  const Column* col = frame.columns.find(field);
  if (!col) {
    const Column* sigma = frame.columns.find("sigma");
    const Column* vel = frame.columns.find("v");
    if ((field == "pressure" || field == "von_mises") && sigma && is_voigt(sigma->info())) {
      if (component > 0)
        throw InputError("render", "'" + field + "' is a scalar; component must be -1 or 0");
      const bool p = field == "pressure";
#pragma omp parallel for schedule(static)
      for (std::size_t i = 0; i < n; ++i) {
        const Sym s = voigt_at(*sigma, i);
        v[i] = float(p ? -trace(s) / 3.0 : von_mises(s));
      }
      out.label = field;
      out.unit = sigma->info().unit.empty() ? "Pa" : sigma->info().unit;
      return out;
    }
    if (field == "speed" && vel && is_floating(vel->info().type)) {
      if (component > 0)
        throw InputError("render", "'speed' is a scalar; component must be -1 or 0");
      const int nc = vel->info().components;
      const bool f64 = vel->info().type == ScalarType::F64;
#pragma omp parallel for schedule(static)
      for (std::size_t i = 0; i < n; ++i) {
        double s = 0;
        for (int k = 0; k < nc; ++k) {
          const double c = f64 ? value_at<double>(*vel, i, k) : value_at<float>(*vel, i, k);
          s += c * c;
        }
        v[i] = float(std::sqrt(s));
      }
      out.label = "speed";
      out.unit = unit_of(vel->info());
      return out;
    }
    unknown_field(frame, field);
  }
  const ColumnInfo& info = col->info();
  const int nc = info.components;
  if (component < -1 || component >= nc)
    throw InputError("render", "field '" + field + "' has " + std::to_string(nc) +
                                   " component(s); component " + std::to_string(component) +
                                   " does not exist (use -1 for the magnitude)");
  out.unit = unit_of(info);
  static const char* voigt_names[] = {"xx", "yy", "zz", "yz", "xz", "xy"};
  static const char* axis_names[] = {"x", "y", "z"};
  if (nc == 1) {
    out.label = field;
  } else if (component >= 0) {
    out.label = field + "_" +
                (is_voigt(info) ? voigt_names[component]
                 : nc <= 3      ? axis_names[component]
                                : std::to_string(component));
  } else if (is_voigt(info)) {
    out.label = field == "sigma" ? "von_mises" : "von Mises " + field;
  } else {
    out.label = "|" + field + "|";
  }
  visit_scalar(info.type, [&](auto tag) {
    using T = decltype(tag);
    const T* src = raw<T>(*col);
    if (component >= 0 || nc == 1) {
      const int k = std::max(component, 0);
#pragma omp parallel for schedule(static)
      for (std::size_t i = 0; i < n; ++i) v[i] = float(src[i * nc + k]);
    } else if (is_voigt(info)) {
#pragma omp parallel for schedule(static)
      for (std::size_t i = 0; i < n; ++i) v[i] = float(von_mises(voigt_at(*col, i)));
    } else {
#pragma omp parallel for schedule(static)
      for (std::size_t i = 0; i < n; ++i) {
        double s = 0;
        for (int k = 0; k < nc; ++k) s += double(src[i * nc + k]) * double(src[i * nc + k]);
        v[i] = float(std::sqrt(s));
      }
    }
  });
  return out;
}

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

/// Camera direction of projection and view-up of a named view.
void view_vectors(const std::string& view, int dim, std::array<double, 3>& dir,
                  std::array<double, 3>& up) {
  if (dim == 2) {  // the picture plane is the model plane whatever the view
    dir = {0, 0, -1}, up = {0, 1, 0};
    return;
  }
  const double r3 = 1.0 / std::sqrt(3.0);
  if (view == "side")
    dir = {0, -1, 0}, up = {0, 0, 1};
  else if (view == "front")
    dir = {-1, 0, 0}, up = {0, 0, 1};
  else if (view == "top")
    dir = {0, 0, -1}, up = {0, 1, 0};
  else if (view == "iso")
    dir = {-r3, -r3, -r3}, up = {0, 0, 1};
}

void check_view(const std::string& view) {
  if (view != "side" && view != "front" && view != "top" && view != "iso")
    throw InputError("render", "unknown view '" + view + "'; use side, front, top or iso");
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

/// A connection to the X display, opened by us and handed to VTK's render window.
/// VTK's X render window aborts the process when it cannot connect; opening the display first
/// turns that into an error. Holding the connection for the whole render also keeps an Xvfb
/// started without -noreset from resetting (and refusing connections) between clients.
/// Xlib is already loaded with VTK's OpenGL module; it is looked up at run time rather than
/// linked. When Xlib is not found, get() is null and VTK connects by itself.
class XDisplay {
 public:
  explicit XDisplay(const char* name) {
    void* open = ::dlsym(RTLD_DEFAULT, "XOpenDisplay");
    close_ = ::dlsym(RTLD_DEFAULT, "XCloseDisplay");
    if (!open || !close_) {
      void* lib = ::dlopen("libX11.so.6", RTLD_LAZY | RTLD_LOCAL);
      if (!lib) return;
      open = ::dlsym(lib, "XOpenDisplay");
      close_ = ::dlsym(lib, "XCloseDisplay");
      if (!open || !close_) return;
    }
    xlib_ = true;
    // A server that is resetting refuses connections for a moment: try for about a second.
    for (int attempt = 0; attempt < 10 && !display_; ++attempt) {
      if (attempt > 0) ::usleep(100000);
      display_ = reinterpret_cast<void* (*)(const char*)>(open)(name);
    }
  }
  ~XDisplay() {
    if (display_) reinterpret_cast<int (*)(void*)>(close_)(display_);
  }
  XDisplay(const XDisplay&) = delete;
  XDisplay& operator=(const XDisplay&) = delete;
  /// False when Xlib was found and the display could not be opened.
  bool ok() const { return !xlib_ || display_; }
  void* get() const { return display_; }

 private:
  bool xlib_ = false;
  void* display_ = nullptr;
  void* close_ = nullptr;
};

/// Sphere impostor for vtkPointGaussianMapper: a disc of radius 1 (in splat units), shaded
/// as the front half of a ball lit from the viewer.
constexpr const char* kSphereSplat =
    "//VTK::Color::Impl\n"
    "float dist2 = dot(offsetVCVSOutput.xy, offsetVCVSOutput.xy);\n"
    "if (dist2 > 1.0) { discard; }\n"
    "float shade = 0.55 + 0.45 * sqrt(1.0 - dist2);\n"
    "ambientColor *= shade;\n"
    "diffuseColor *= shade;\n";

}  // namespace

// ---------------------------------------------------------------------------------------------

/// Time fields and the write of an unstructured grid as an appended, zlib-compressed .vtu,
/// through a temporary file committed only when the write succeeded: "TIME" (VisIt convention,
/// shown by ParaView's Annotate Time Filter), "TimeValue" (what VTK's and ParaView's XML readers
/// use as the time of a lone file or file series), and the step as "CYCLE".
static void write_unstructured(vtkUnstructuredGrid* grid, double time, std::int64_t step,
                               const std::string& path) {
  vtkFieldData* fd = grid->GetFieldData();
  add_field_value<vtkDoubleArray>(fd, "TIME", time);
  add_field_value<vtkDoubleArray>(fd, "TimeValue", time);
  add_field_value<vtkTypeInt64Array>(fd, "CYCLE", vtkTypeInt64(step));

  FileTarget target(path);
  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  vtkNew<ErrorCatcher> errors, pipeline_errors;
  writer->AddObserver(vtkCommand::ErrorEvent, errors);
  writer->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, pipeline_errors);
  writer->SetInputData(grid);
  writer->SetFileName(target.write_path().c_str());
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();  // raw binary, not base64
  writer->SetCompressorTypeToZLib();
  writer->SetCompressionLevel(1);   // fastest zlib: 4x smaller here, level 5 takes 3x as long
  writer->SetHeaderTypeToUInt64();  // blocks and arrays beyond 4 GiB
  writer->SetIdTypeToInt64();
  const int ok = writer->Write();
  if (!ok || writer->GetErrorCode() != 0 || !errors->message.empty() ||
      !pipeline_errors->message.empty())
    throw IoError("cannot write " + path + ": " +
                  writer_failure(*errors, writer->GetErrorCode(), *pipeline_errors,
                                 target.write_path(), path));
  target.commit();
}

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
    const int nc = vel->info().components;
    const bool f64 = vel->info().type == ScalarType::F64;
#pragma omp parallel for schedule(static)
    for (std::size_t i = 0; i < n; ++i) {
      double s = 0;
      for (int k = 0; k < nc; ++k) {
        const double c = f64 ? value_at<double>(*vel, i, k) : value_at<float>(*vel, i, k);
        s += c * c;
      }
      d[i] = std::sqrt(s);
    }
    pd->AddArray(sp);
  }

  write_unstructured(grid, frame.time, frame.step, path);
}

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
  write_unstructured(grid, mesh.time, mesh.step, path);
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

void render_png(const Frame& frame, int dim, const RenderOptions& options,
                const std::string& path) {
  // Everything about the input is checked before a window is opened.
  const Column& x = positions(frame, dim, "render");
  const std::size_t n = frame.columns.size();
  if (n == 0) throw InputError("render", "the frame has no particles");
  check_view(options.view);
  if (options.width < 16 || options.height < 16 || options.width > 16384 || options.height > 16384)
    throw InputError("render", "picture size " + std::to_string(options.width) + "x" +
                                   std::to_string(options.height) + " is out of range (16..16384)");
  if (options.range_given && !(options.range_max > options.range_min))
    throw InputError("render", "the colour range must have max > min");
  if (options.point_radius < 0 || !std::isfinite(options.point_radius))
    throw InputError("render", "the point radius must be positive (or 0 for automatic)");
  FieldValues field = evaluate_field(frame, options.field, options.component);
  const Clip clip = parse_clip(options.clip, dim);
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

  // Particles kept by the clip.
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
    if (keep.empty()) throw InputError("render", "clip '" + options.clip + "' leaves no particles");
  }
  const std::size_t nk = keep.size();
  if (options.mirror && dim != 2)
    throw InputError("render", "mirroring is for 2D (axisymmetric) frames");
  const std::size_t np = options.mirror ? 2 * nk : nk;  // mirrored copies after the particles

  // Colour range: given, else the field's finite min..max over the frame.
  double lo = options.range_min, hi = options.range_max;
  if (!options.range_given) {
    lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (float v : field.values)
      if (std::isfinite(v)) lo = std::min(lo, double(v)), hi = std::max(hi, double(v));
    if (!(lo <= hi)) lo = 0, hi = 1;
    if (hi - lo <= 1e-12 * std::max(std::abs(lo), std::abs(hi))) {
      const double pad = lo == 0 ? 1.0 : 0.01 * std::abs(lo);
      lo -= pad, hi += pad;
    }
  }

  // Poly data of the kept particles: float positions and the field as scalars.
  vtkNew<vtkFloatArray> xyz;
  xyz->SetNumberOfComponents(3);
  xyz->SetNumberOfTuples(vtkIdType(np));
  vtkNew<vtkFloatArray> scalars;
  scalars->SetName(field.label.c_str());
  scalars->SetNumberOfTuples(vtkIdType(np));
  float* pxyz = xyz->GetPointer(0);
  float* ps = scalars->GetPointer(0);
#pragma omp parallel for schedule(static)
  for (std::size_t j = 0; j < nk; ++j) {
    const auto p = position(x, keep[j]);
    pxyz[3 * j] = float(p[0]), pxyz[3 * j + 1] = float(p[1]), pxyz[3 * j + 2] = float(p[2]);
    ps[j] = field.values[keep[j]];
    if (np > nk) {
      float* q = pxyz + 3 * (nk + j);
      q[0] = -float(p[0]), q[1] = float(p[1]), q[2] = float(p[2]);
      ps[nk + j] = ps[j];
    }
  }
  double bounds[6] = {
      std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
      std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
      std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  for (std::size_t j = 0; j < np; ++j)
    for (int a = 0; a < 3; ++a)
      bounds[2 * a] = std::min(bounds[2 * a], double(pxyz[3 * j + a])),
                 bounds[2 * a + 1] = std::max(bounds[2 * a + 1], double(pxyz[3 * j + a]));
  const double radius = options.point_radius > 0
                            ? options.point_radius
                            : estimate_radius(frame, dim, options.axisymmetric, keep, bounds);

  vtkNew<vtkPoints> points;
  points->SetData(xyz);
  vtkNew<vtkPolyData> poly;
  poly->SetPoints(points);
  poly->GetPointData()->SetScalars(scalars);

  auto lut = viridis_table(lo, hi);
  vtkNew<vtkPointGaussianMapper> mapper;
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
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  actor->GetProperty()->SetAmbient(0.0);
  actor->GetProperty()->SetDiffuse(1.0);

  // The particles fill a viewport left of the colour bar and below the title, drawn over a
  // window-wide white renderer that holds the title and the colour bar.
  const double scene_vp[4] = {0.0, 0.0, 0.84, 0.92};
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

  const double dark[3] = {0.1, 0.1, 0.12};
  const int h = options.height, w = options.width;
  std::string bar_title = field.label;
  if (!field.unit.empty() && field.unit != "-" && field.unit != "1")
    bar_title += " (" + field.unit + ")";
  vtkNew<vtkScalarBarActor> bar;
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
    tp->SetColor(dark[0], dark[1], dark[2]);
    tp->ShadowOff();
    tp->ItalicOff();
    tp->SetFontFamilyToArial();
  }
  bar->GetTitleTextProperty()->SetFontSize(std::max(10, h / 42));
  bar->GetTitleTextProperty()->BoldOn();
  bar->GetLabelTextProperty()->SetFontSize(std::max(9, h / 50));
  bar->GetLabelTextProperty()->BoldOff();
  overlay->AddViewProp(bar);

  const std::string title =
      options.title.empty() ? field.label + " at t = " + format_time(frame.time) : options.title;
  vtkNew<vtkTextActor> text;
  text->SetInput(title.c_str());
  text->SetTextScaleModeToNone();
  vtkTextProperty* tp = text->GetTextProperty();
  tp->SetFontSize(std::max(12, h / 28));
  tp->SetColor(dark[0], dark[1], dark[2]);
  tp->SetJustificationToCentered();
  tp->SetVerticalJustificationToTop();
  tp->SetFontFamilyToArial();
  tp->BoldOn();
  tp->ShadowOff();
  text->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  text->GetPositionCoordinate()->SetValue(0.5, 0.975);
  overlay->AddViewProp(text);

  vtkNew<vtkRenderWindow> window;
  if (x_display.get()) window->SetDisplayId(x_display.get());
  window->SetOffScreenRendering(1);
  window->SetMultiSamples(0);
  window->SetNumberOfLayers(2);
  window->AddRenderer(scene);
  window->AddRenderer(overlay);
  window->SetSize(w, h);

  // Camera: parallel projection fitted to the particles' bounding box seen from the view,
  // with a margin of one particle radius and 6 %.
  std::array<double, 3> dir{}, up{};
  view_vectors(options.view, dim, dir, up);
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
  camera->SetViewUp(up.data());
  scene->ResetCamera(bounds);  // sets the distance and clipping range around the bounds
  camera->SetFocalPoint(centre);
  // Half extents of the bounding box along the screen's right and up directions.
  const std::array<double, 3> right{dir[1] * up[2] - dir[2] * up[1],
                                    dir[2] * up[0] - dir[0] * up[2],
                                    dir[0] * up[1] - dir[1] * up[0]};
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
  // Particles smaller than a pixel would fall between the pixel centres and vanish.
  const double pixel = 2 * scale / ((scene_vp[3] - scene_vp[1]) * h);
  mapper->SetScaleFactor(std::max(radius, 0.75 * pixel));
  scene->ResetCameraClippingRange(bounds[0] - radius, bounds[1] + radius, bounds[2] - radius,
                                  bounds[3] + radius, bounds[4] - radius, bounds[5] + radius);

  // The filter renders the window once (its ShouldRerender) and reads the back buffer.
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();
  FileTarget target(path);
  vtkNew<vtkPNGWriter> png;
  vtkNew<ErrorCatcher> png_errors, pipeline_errors;
  png->AddObserver(vtkCommand::ErrorEvent, png_errors);
  png->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, pipeline_errors);
  png->SetInputConnection(grab->GetOutputPort());
  png->SetFileName(target.write_path().c_str());
  png->Write();
  if (png->GetErrorCode() != 0 || !png_errors->message.empty() || !pipeline_errors->message.empty())
    throw IoError("cannot write " + path + ": " +
                  writer_failure(*png_errors, png->GetErrorCode(), *pipeline_errors,
                                 target.write_path(), path));
  target.commit();
}

void ensure_display(int argc, char** argv) {
  const char* display = std::getenv("DISPLAY");
  if (display && *display) return;
  const char* under = std::getenv("MPM_UNDER_XVFB");
  if (under && *under)
    throw InputError("render",
                     "no display even under xvfb-run (MPM_UNDER_XVFB is set but DISPLAY is not); "
                     "check that Xvfb starts (xvfb-run -a xdpyinfo) or set DISPLAY");
  ::setenv("MPM_UNDER_XVFB", "1", 1);

  // Re-run this very program: /proc/self/exe survives a relative argv[0] or a changed PATH.
  std::string self;
  char buf[4096];
  const ssize_t len = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (len > 0)
    self.assign(buf, std::size_t(len));
  else if (argc > 0 && argv && argv[0])
    self = argv[0];
  std::vector<std::string> args = {"xvfb-run", "-a", "-s", "-screen 0 1920x1080x24 -noreset", self};
  for (int i = 1; i < argc; ++i) args.emplace_back(argv[i]);
  std::vector<char*> cargs;
  for (auto& a : args) cargs.push_back(a.data());
  cargs.push_back(nullptr);
  std::fflush(nullptr);  // stdio buffers do not survive exec
  ::execvp("xvfb-run", cargs.data());
  ::unsetenv("MPM_UNDER_XVFB");
  throw InputError("render", "no display and no xvfb-run; install xvfb or set DISPLAY");
}

}  // namespace mpm
