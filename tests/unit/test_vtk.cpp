// ParaView output and off-screen pictures: write_vtu, write_pvd, render_png, ensure_display.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnsignedIntArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLDataParser.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "mpm/core/error.hpp"
#include "mpm/core/types.hpp"
#include "mpm/post/vtk/vtk_output.hpp"

namespace fs = std::filesystem;
using namespace mpm;

namespace {

/// Sets or clears an environment variable for one scope.
struct ScopedEnv {
  std::string name;
  bool had = false;
  std::string old;
  ScopedEnv(const char* n, const char* value) : name(n) {
    if (const char* v = std::getenv(n)) had = true, old = v;
    if (value)
      ::setenv(n, value, 1);
    else
      ::unsetenv(n);
  }
  ~ScopedEnv() {
    if (had)
      ::setenv(name.c_str(), old.c_str(), 1);
    else
      ::unsetenv(name.c_str());
  }
};

/// A fresh directory under the system temp dir, removed at the end of the test.
struct TempDir {
  fs::path path;
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path = fs::temp_directory_path() /
           ("mpm_vtk_" + std::string(info ? info->name() : "x") + "_" + std::to_string(::getpid()));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string operator/(const std::string& name) const { return (path / name).string(); }
};

/// Sigma of particle i: six distinct, particle-dependent values (Voigt xx, yy, zz, yz, xz, xy).
Sym sigma_of(std::size_t i) {
  Sym s;
  for (int k = 0; k < 6; ++k) s[k] = 1e6 * (double(k + 1) + 0.01 * double(i)) * (k % 2 ? -1 : 1);
  return s;
}

/// A frame with every kind of column: a block of particles on a lattice (dim = 2 or 3).
Frame make_frame(int dim, std::size_t n, double time = 12.3e-6, std::int64_t step = 42) {
  Frame f;
  f.step = step;
  f.time = time;
  ColumnStore& c = f.columns;
  c.add({"id", ScalarType::U32, 1, "-"});
  c.add({"body", ScalarType::U8, 1, "-"});
  c.add({"material", ScalarType::U8, 1, "-"});
  c.add({"x", ScalarType::F64, dim, "m"});
  c.add({"v", ScalarType::F64, dim, "m/s"});
  c.add({"m", ScalarType::F64, 1, "kg"});
  c.add({"rho", ScalarType::F64, 1, "kg/m^3"});
  c.add({"sigma", ScalarType::F64, 6, "Pa"});
  c.add({"e", ScalarType::F64, 1, "J/kg"});
  c.add({"eps_p", ScalarType::F64, 1, "-"});
  c.add({"T", ScalarType::F64, 1, "K"});
  c.add({"failed", ScalarType::U8, 1, "-"});
  c.add({"extra_i32", ScalarType::I32, 1, ""});
  c.resize(n);
  const double h = 1e-3;  // lattice spacing: a 10 x 4 x k block of 1 mm particles
  auto* id = c.get<std::uint32_t>("id");
  auto* body = c.get<std::uint8_t>("body");
  auto* mat = c.get<std::uint8_t>("material");
  double* x = reinterpret_cast<double*>(c.at("x").data());
  double* v = reinterpret_cast<double*>(c.at("v").data());
  auto* m = c.get<double>("m");
  auto* rho = c.get<double>("rho");
  auto* sig = c.get<Sym>("sigma");
  auto* e = c.get<double>("e");
  auto* eps = c.get<double>("eps_p");
  auto* T = c.get<double>("T");
  auto* failed = c.get<std::uint8_t>("failed");
  auto* extra = c.get<std::int32_t>("extra_i32");
  for (std::size_t i = 0; i < n; ++i) {
    id[i] = std::uint32_t(1000 + i);
    body[i] = std::uint8_t(i % 2);
    mat[i] = std::uint8_t(i % 3);
    // 3D: a bar of 10 x 4 x (n / 40) particles (a cube when n is large); 2D: a block 40
    // particles wide.
    const std::size_t a = std::max<std::size_t>(10, std::size_t(std::cbrt(double(n)) + 0.5));
    const std::size_t b = a == 10 ? 4 : a;
    const double pos[3] = {h * double(i % a), h * double((i / a) % b), h * double(i / (a * b))};
    const double pos2[2] = {h * double(i % 40), h * double(i / 40)};
    for (int k = 0; k < dim; ++k) {
      x[dim * i + k] = dim == 3 ? pos[k] : pos2[k];
      v[dim * i + k] = double(k + 1) * 10.0 + 0.5 * double(i);
    }
    rho[i] = 8930;
    m[i] = dim == 3 ? 8930 * h * h * h : 8930 * h * h;  // 2D: mass per metre of thickness
    sig[i] = sigma_of(i);
    e[i] = 100.0 * double(i);
    eps[i] = 1e-3 * double(i);
    T[i] = 293.15 + double(i);
    failed[i] = std::uint8_t(i % 7 == 0);
    extra[i] = -int(i);
  }
  return f;
}

vtkSmartPointer<vtkUnstructuredGrid> read_vtu(const std::string& path) {
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkSmartPointer<vtkUnstructuredGrid> grid = reader->GetOutput();
  return grid;
}

/// Checks a .vtu written from `f` against the frame, column by column.
void check_vtu(const Frame& f, int dim, vtkUnstructuredGrid* g) {
  const std::size_t n = f.columns.size();
  ASSERT_NE(g, nullptr);
  ASSERT_EQ(g->GetNumberOfPoints(), vtkIdType(n));
  ASSERT_EQ(g->GetNumberOfCells(), vtkIdType(n));
  EXPECT_EQ(g->GetCellType(0), VTK_VERTEX);
  EXPECT_EQ(g->GetCellType(vtkIdType(n - 1)), VTK_VERTEX);
  const double* x = reinterpret_cast<const double*>(f.columns.at("x").data());
  for (std::size_t i = 0; i < n; ++i) {
    double p[3];
    g->GetPoint(vtkIdType(i), p);
    for (int k = 0; k < 3; ++k) ASSERT_EQ(p[k], k < dim ? x[dim * i + k] : 0.0) << i << " " << k;
  }
  // Exactly: every column but x, and the derived fields.
  vtkPointData* pd = g->GetPointData();
  std::set<std::string> names;
  for (int a = 0; a < pd->GetNumberOfArrays(); ++a) names.insert(pd->GetArrayName(a));
  std::set<std::string> expected = {"id",     "body",      "material", "v",         "m",
                                    "rho",    "sigma",     "e",        "eps_p",     "T",
                                    "failed", "extra_i32", "pressure", "von_mises", "speed"};
  EXPECT_EQ(names, expected);

  // Every column: type, component count, values.
  for (const Column& c : f.columns.columns()) {
    const ColumnInfo& info = c.info();
    if (info.name == "x") continue;
    SCOPED_TRACE(info.name);
    vtkDataArray* a = pd->GetArray(info.name.c_str());
    ASSERT_NE(a, nullptr);
    ASSERT_EQ(a->GetNumberOfTuples(), vtkIdType(n));
    int expected_type = VTK_DOUBLE;
    if (info.type == ScalarType::U8) expected_type = VTK_UNSIGNED_CHAR;
    if (info.type == ScalarType::U32) expected_type = VTK_UNSIGNED_INT;
    if (info.type == ScalarType::I32) expected_type = VTK_INT;
    EXPECT_EQ(a->GetDataType(), expected_type);
    if (info.name == "sigma") {
      ASSERT_EQ(a->GetNumberOfComponents(), 6);
      // VTK order xx, yy, zz, xy, yz, xz from Voigt xx, yy, zz, yz, xz, xy.
      const int from[6] = {0, 1, 2, 5, 3, 4};
      for (std::size_t i = 0; i < n; ++i) {
        const Sym s = sigma_of(i);
        for (int k = 0; k < 6; ++k) ASSERT_EQ(a->GetComponent(vtkIdType(i), k), s[from[k]]);
      }
      continue;
    }
    const int nc = info.components;
    const int padded = (dim == 2 && nc == 2) ? 3 : nc;
    ASSERT_EQ(a->GetNumberOfComponents(), padded);
    for (std::size_t i = 0; i < n; ++i) {
      for (int k = 0; k < padded; ++k) {
        double want = 0;
        if (k < nc) {
          switch (info.type) {
            case ScalarType::F64:
              want = reinterpret_cast<const double*>(c.data())[i * nc + k];
              break;
            case ScalarType::U8:
              want = reinterpret_cast<const std::uint8_t*>(c.data())[i * nc + k];
              break;
            case ScalarType::U32:
              want = reinterpret_cast<const std::uint32_t*>(c.data())[i * nc + k];
              break;
            case ScalarType::I32:
              want = reinterpret_cast<const std::int32_t*>(c.data())[i * nc + k];
              break;
            default:
              FAIL() << "unexpected type";
          }
        }
        ASSERT_EQ(a->GetComponent(vtkIdType(i), k), want) << i << " " << k;
      }
    }
  }

  // Derived fields, against independent formulas.
  vtkDataArray* p = pd->GetArray("pressure");
  vtkDataArray* vm = pd->GetArray("von_mises");
  vtkDataArray* speed = pd->GetArray("speed");
  ASSERT_TRUE(p && vm && speed);
  EXPECT_EQ(p->GetNumberOfComponents(), 1);
  EXPECT_EQ(vm->GetNumberOfComponents(), 1);
  const double* v = reinterpret_cast<const double*>(f.columns.at("v").data());
  for (std::size_t i = 0; i < n; ++i) {
    const Sym s = sigma_of(i);
    const double pr = -(s[0] + s[1] + s[2]) / 3.0;
    const double vme =
        std::sqrt(0.5 * ((s[0] - s[1]) * (s[0] - s[1]) + (s[1] - s[2]) * (s[1] - s[2]) +
                         (s[2] - s[0]) * (s[2] - s[0])) +
                  3.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]));
    ASSERT_NEAR(p->GetTuple1(vtkIdType(i)), pr, 1e-9 * std::abs(pr) + 1e-6);
    ASSERT_NEAR(vm->GetTuple1(vtkIdType(i)), vme, 1e-9 * vme);
    double s2 = 0;
    for (int k = 0; k < dim; ++k) s2 += v[dim * i + k] * v[dim * i + k];
    ASSERT_NEAR(speed->GetTuple1(vtkIdType(i)), std::sqrt(s2), 1e-12 * std::sqrt(s2));
  }

  // Time in the field data.
  vtkFieldData* fd = g->GetFieldData();
  ASSERT_NE(fd->GetArray("TIME"), nullptr);
  EXPECT_EQ(fd->GetArray("TIME")->GetNumberOfTuples(), 1);
  EXPECT_EQ(fd->GetArray("TIME")->GetTuple1(0), f.time);
  ASSERT_NE(fd->GetArray("TimeValue"), nullptr);
  EXPECT_EQ(fd->GetArray("TimeValue")->GetTuple1(0), f.time);
  ASSERT_NE(fd->GetArray("CYCLE"), nullptr);
  EXPECT_EQ(fd->GetArray("CYCLE")->GetTuple1(0), double(f.step));
}

}  // namespace

TEST(Vtk, WritesVtu3DWithEveryColumn) {
  TempDir dir;
  const Frame f = make_frame(3, 400);
  const std::string path = dir / "frame.vtu";
  write_vtu(f, 3, path);
  // Appended raw binary, zlib-compressed.
  std::ifstream in(path, std::ios::binary);
  const std::string head((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(head.find("compressor=\"vtkZLibDataCompressor\""), std::string::npos);
  EXPECT_NE(head.find("format=\"appended\""), std::string::npos);
  EXPECT_NE(head.find("<AppendedData encoding=\"raw\""), std::string::npos)
      << "AppendedData should be raw";
  auto g = read_vtu(path);
  check_vtu(f, 3, g);
}

TEST(Vtk, WritesVtu2DWithPaddedVectors) {
  TempDir dir;
  const Frame f = make_frame(2, 123, 0.5e-3, 7);
  const std::string path = dir / "frame2d.vtu";
  write_vtu(f, 2, path);
  auto g = read_vtu(path);
  check_vtu(f, 2, g);
  EXPECT_EQ(g->GetPointData()->GetArray("v")->GetNumberOfComponents(), 3);
  EXPECT_EQ(g->GetPointData()->GetArray("v")->GetComponent(5, 2), 0.0);
}

TEST(Vtk, WritesEmptyFrame) {
  TempDir dir;
  const Frame f = make_frame(3, 0);
  write_vtu(f, 3, dir / "empty.vtu");
  auto g = read_vtu(dir / "empty.vtu");
  EXPECT_EQ(g->GetNumberOfPoints(), 0);
  EXPECT_EQ(g->GetFieldData()->GetArray("TIME")->GetTuple1(0), f.time);
}

TEST(Vtk, WriteFailuresThrowIoError) {
  TempDir dir;
  const Frame f = make_frame(3, 10);
  EXPECT_THROW(write_vtu(f, 3, dir / "missing/dir/frame.vtu"), IoError);
  EXPECT_FALSE(fs::exists(dir / "missing"));
  EXPECT_THROW(write_pvd({{0.0, "a.vtu"}}, dir / "missing/run.pvd"), IoError);
  // A full disk: an error, and a special file is written in place, never removed or replaced.
  if (fs::is_character_file("/dev/full")) {
    EXPECT_THROW(write_vtu(f, 3, "/dev/full"), IoError);
    EXPECT_THROW(write_pvd({{0.0, "a.vtu"}}, "/dev/full"), IoError);
    EXPECT_TRUE(fs::is_character_file("/dev/full"));
  }
  // Rewriting a file replaces it whole and leaves no temporary file behind.
  write_vtu(f, 3, dir / "frame.vtu");
  write_vtu(make_frame(3, 20), 3, dir / "frame.vtu");
  EXPECT_EQ(read_vtu(dir / "frame.vtu")->GetNumberOfPoints(), 20);
  std::size_t files = 0;
  for (auto& e : fs::directory_iterator(dir.path)) files += e.is_regular_file();
  EXPECT_EQ(files, 1u);
  // Bad input is the user's mistake, not an I/O failure.
  EXPECT_THROW(write_vtu(f, 4, dir / "frame.vtu"), InputError);
  EXPECT_THROW(write_vtu(f, 2, dir / "frame.vtu"), InputError);  // x has 3 components
}

TEST(Vtk, WritesPvdCollectionReadableWithTheFrames) {
  TempDir dir;
  fs::create_directories(dir.path / "frames");
  std::vector<std::pair<double, std::string>> entries;
  const double times[3] = {0.0, 1.25e-6, 2.5e-6};
  for (int k = 0; k < 3; ++k) {
    const std::string name = "frames/run_" + std::to_string(k) + ".vtu";
    write_vtu(make_frame(3, 50 + k, times[k], k * 100), 3, dir / name);
    entries.emplace_back(times[k], name);
  }
  entries[2].second = "frames/run_2.vtu";
  write_pvd(entries, dir / "run.pvd");
  EXPECT_FALSE(fs::exists(dir / ("run.pvd.tmp" + std::to_string(::getpid()))));

  // VTK 9.1 has no vtkXMLCollectionReader (it is ParaView's): parse the XML with VTK's
  // parser, check it, and read every referenced file.
  vtkNew<vtkXMLDataParser> parser;
  const std::string pvd = dir / "run.pvd";
  parser->SetFileName(pvd.c_str());
  ASSERT_EQ(parser->Parse(), 1);
  vtkXMLDataElement* root = parser->GetRootElement();
  ASSERT_NE(root, nullptr);
  EXPECT_STREQ(root->GetName(), "VTKFile");
  EXPECT_STREQ(root->GetAttribute("type"), "Collection");
  vtkXMLDataElement* coll = root->FindNestedElementWithName("Collection");
  ASSERT_NE(coll, nullptr);
  ASSERT_EQ(coll->GetNumberOfNestedElements(), 3);
  for (int k = 0; k < 3; ++k) {
    vtkXMLDataElement* ds = coll->GetNestedElement(k);
    EXPECT_STREQ(ds->GetName(), "DataSet");
    double t = -1;
    ASSERT_TRUE(ds->GetScalarAttribute("timestep", t));
    EXPECT_EQ(t, times[k]);
    ASSERT_NE(ds->GetAttribute("file"), nullptr);
    EXPECT_EQ(std::string(ds->GetAttribute("file")), entries[k].second);
    auto g = read_vtu((dir.path / ds->GetAttribute("file")).string());
    ASSERT_EQ(g->GetNumberOfPoints(), 50 + k);
    EXPECT_EQ(g->GetFieldData()->GetArray("TIME")->GetTuple1(0), t);
  }
}

TEST(Vtk, PvdEscapesFileNames) {
  TempDir dir;
  write_pvd({{1.0, "a&b <\"c\">.vtu"}}, dir / "odd.pvd");
  vtkNew<vtkXMLDataParser> parser;
  const std::string pvd = dir / "odd.pvd";
  parser->SetFileName(pvd.c_str());
  ASSERT_EQ(parser->Parse(), 1);
  vtkXMLDataElement* ds =
      parser->GetRootElement()->FindNestedElementWithName("Collection")->GetNestedElement(0);
  EXPECT_EQ(std::string(ds->GetAttribute("file")), "a&b <\"c\">.vtu");
}

TEST(Vtk, RenderRejectsBadOptionsBeforeOpeningAWindow) {
  TempDir dir;
  const Frame f = make_frame(3, 100);
  RenderOptions o;
  o.field = "temperature";
  try {
    render_png(f, 3, o, dir / "x.png");
    FAIL() << "an unknown field was accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("unknown field 'temperature'"), std::string::npos) << msg;
    for (const char* name : {"eps_p", "sigma", "T", "pressure", "von_mises", "speed", "id"})
      EXPECT_NE(msg.find(name), std::string::npos) << name << " not listed in: " << msg;
  }
  o.field = "v";
  o.component = 3;
  EXPECT_THROW(render_png(f, 3, o, dir / "x.png"), InputError);
  o.component = -1;
  o.view = "sideways";
  EXPECT_THROW(render_png(f, 3, o, dir / "x.png"), InputError);
  o.view = "side";
  o.clip = "w>0";
  EXPECT_THROW(render_png(f, 3, o, dir / "x.png"), InputError);
  o.clip = "z>0";
  EXPECT_THROW(render_png(make_frame(2, 10), 2, o, dir / "x.png"), InputError);
  // No display, or one that cannot be opened: an error, not VTK's abort().
  o.clip.clear();
  {
    ScopedEnv d("DISPLAY", nullptr);
    EXPECT_THROW(render_png(f, 3, o, dir / "x.png"), InputError);
  }
  {
    ScopedEnv d("DISPLAY", ":12345");
    try {
      render_png(f, 3, o, dir / "x.png");
      FAIL() << "no exception";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("cannot open the X display ':12345'"), std::string::npos)
          << e.what();
    }
  }
  EXPECT_FALSE(fs::exists(dir / "x.png"));
}

namespace {

std::string self_exe() {
  return fs::read_symlink("/proc/self/exe").string();
}

/// Runs this test binary's helper test VtkRenderChild.Render in a child process with no
/// DISPLAY, so that ensure_display re-runs it under xvfb-run. Returns the exit status
/// (77: no xvfb-run).
int run_render_child(const std::string& out_dir, std::size_t particles) {
  const std::string exe = self_exe();
  std::fflush(nullptr);  // else the child's exec path flushes the parent's buffered output too
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::unsetenv("DISPLAY");
    ::unsetenv("MPM_UNDER_XVFB");
    ::setenv("MPM_TEST_RENDER_DIR", out_dir.c_str(), 1);
    ::setenv("MPM_TEST_RENDER_N", std::to_string(particles).c_str(), 1);
    std::string a0 = exe, a1 = "--gtest_filter=VtkRenderChild.Render", a2 = "--gtest_brief=1";
    char* argv[] = {a0.data(), a1.data(), a2.data(), nullptr};
    try {
      ensure_display(3, argv);
    } catch (const InputError& e) {
      std::fprintf(stderr, "%s\n", e.what());
      ::_exit(77);
    }
    ::_exit(78);  // ensure_display returned with no DISPLAY
  }
  int status = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(300);
  while (::waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

struct Picture {
  int width = 0, height = 0;
  std::map<std::uint32_t, std::size_t> colours;  // 0xRRGGBB -> pixel count
  std::size_t pixels() const { return std::size_t(width) * std::size_t(height); }
  std::size_t count_near(int r, int g, int b, int tol) const {
    std::size_t k = 0;
    for (auto& [c, cnt] : colours)
      if (std::abs(int(c >> 16) - r) <= tol && std::abs(int((c >> 8) & 255) - g) <= tol &&
          std::abs(int(c & 255) - b) <= tol)
        k += cnt;
    return k;
  }
  std::size_t count_if(auto pred) const {
    std::size_t k = 0;
    for (auto& [c, cnt] : colours)
      if (pred(int(c >> 16), int((c >> 8) & 255), int(c & 255))) k += cnt;
    return k;
  }
};

Picture read_png(const std::string& path) {
  Picture p;
  vtkNew<vtkPNGReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkImageData* img = reader->GetOutput();
  int dims[3];
  img->GetDimensions(dims);
  p.width = dims[0], p.height = dims[1];
  const int nc = img->GetNumberOfScalarComponents();
  auto* px = static_cast<unsigned char*>(img->GetScalarPointer());
  if (!px || nc < 3) return p;
  for (std::size_t i = 0; i < p.pixels(); ++i) {
    const unsigned char* c = px + i * nc;
    ++p.colours[(std::uint32_t(c[0]) << 16) | (std::uint32_t(c[1]) << 8) | c[2]];
  }
  return p;
}

void check_picture(const Picture& p, int width, int height) {
  ASSERT_EQ(p.width, width);
  ASSERT_EQ(p.height, height);
  const double total = double(p.pixels());
  // White background around the particles.
  EXPECT_GT(double(p.count_near(255, 255, 255, 0)) / total, 0.2);
  // Particles: many distinct colours from the colour map and the sphere shading.
  EXPECT_GT(p.colours.size(), 200u);
  EXPECT_GT(double(p.count_if(
                [](int r, int g, int b) { return std::abs(r - g) + std::abs(g - b) > 60; })) /
                total,
            0.05);
  // The colour bar shows both ends of viridis (dark purple 68,1,84 and yellow 253,231,37).
  EXPECT_GT(p.count_near(68, 1, 84, 12), 20u);
  EXPECT_GT(p.count_near(253, 231, 37, 12), 20u);
  // Dark text: the title and the colour bar labels.
  EXPECT_GT(p.count_if([](int r, int g, int b) { return r < 70 && g < 70 && b < 70; }), 200u);
}

}  // namespace

// Runs only as the child of VtkRender.*: renders pictures into $MPM_TEST_RENDER_DIR.
TEST(VtkRenderChild, Render) {
  const char* out = std::getenv("MPM_TEST_RENDER_DIR");
  if (!out) GTEST_SKIP() << "helper of VtkRender tests; runs in a child process under xvfb-run";
  // Under xvfb-run: ensure_display finds the display and returns.
  char arg0[] = "unused";
  char* argv[] = {arg0, nullptr};
  ASSERT_NO_THROW(ensure_display(1, argv));
  ASSERT_NE(std::getenv("DISPLAY"), nullptr);
  const std::size_t n = std::strtoull(std::getenv("MPM_TEST_RENDER_N"), nullptr, 10);
  const fs::path dir(out);

  const Frame f3 = make_frame(3, n);
  RenderOptions o;
  o.field = "pressure";
  if (n <= 100000) o.width = 640, o.height = 480;  // the benchmark keeps the default size
  o.clip = "y>0";
  auto t0 = std::chrono::steady_clock::now();
  render_png(f3, 3, o, (dir / "side.png").string());
  auto t1 = std::chrono::steady_clock::now();
  std::ofstream(dir / "seconds.txt") << std::chrono::duration<double>(t1 - t0).count() << "\n";
  if (n > 100000) return;  // the benchmark wants the one picture

  o.view = "iso";
  o.field = "v";  // magnitude
  o.clip.clear();
  o.title = "custom title";
  render_png(f3, 3, o, (dir / "iso.png").string());

  const Frame f2 = make_frame(2, 800);
  RenderOptions o2;
  o2.field = "speed";
  o2.width = 500, o2.height = 400;
  render_png(f2, 2, o2, (dir / "flat.png").string());

  EXPECT_THROW(render_png(f3, 3, o, (dir / "missing" / "x.png").string()), IoError);
}

TEST(VtkRender, RendersPngUnderXvfb) {
  TempDir dir;
  const int status = run_render_child(dir.path.string(), 2000);
  if (status == 77) GTEST_SKIP() << "no xvfb-run on this machine";
  ASSERT_EQ(status, 0) << "the render child failed";
  {
    SCOPED_TRACE("side, pressure, clip y>0");
    check_picture(read_png(dir / "side.png"), 640, 480);
  }
  {
    SCOPED_TRACE("iso, |v|");
    check_picture(read_png(dir / "iso.png"), 640, 480);
  }
  {
    SCOPED_TRACE("2D, speed");
    check_picture(read_png(dir / "flat.png"), 500, 400);
  }
  EXPECT_FALSE(fs::exists(dir.path / "missing"));
}

// A million particles, for timing (label `long`).
TEST(VtkRender, LongMillionParticles) {
  if (GTEST_FLAG_GET(filter).find("Long") == std::string::npos)
    GTEST_SKIP() << "long test: select it with --gtest_filter='*Long*' (ctest -L long)";
  TempDir dir;
  const Frame f = make_frame(3, 1000000);
  auto t0 = std::chrono::steady_clock::now();
  write_vtu(f, 3, dir / "million.vtu");
  auto t1 = std::chrono::steady_clock::now();
  std::printf("write_vtu: 1e6 particles in %.2f s, %.1f MB\n",
              std::chrono::duration<double>(t1 - t0).count(),
              double(fs::file_size(dir / "million.vtu")) / 1e6);
  const int status = run_render_child(dir.path.string(), 1000000);
  if (status == 77) GTEST_SKIP() << "no xvfb-run on this machine";
  auto t2 = std::chrono::steady_clock::now();
  ASSERT_EQ(status, 0);
  double seconds = 0;
  std::ifstream(dir / "seconds.txt") >> seconds;
  std::printf("render_png: 1e6 particles in %.2f s (child process with Xvfb: %.2f s)\n", seconds,
              std::chrono::duration<double>(t2 - t1).count());
  check_picture(read_png(dir / "side.png"), RenderOptions{}.width, RenderOptions{}.height);
}

TEST(Vtk, EnsureDisplayReturnsWithADisplayAndRefusesALoop) {
  char arg0[] = "mpm-post";
  char* argv[] = {arg0, nullptr};
  {
    ScopedEnv d("DISPLAY", ":12345");
    EXPECT_NO_THROW(ensure_display(1, argv));
  }
  {
    ScopedEnv d("DISPLAY", nullptr);
    ScopedEnv u("MPM_UNDER_XVFB", "1");
    try {
      ensure_display(1, argv);
      FAIL() << "no exception";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("DISPLAY"), std::string::npos) << e.what();
    }
  }
  {
    // No xvfb-run on the PATH: a clear error, and the guard variable is not left set.
    ScopedEnv d("DISPLAY", nullptr);
    ScopedEnv u("MPM_UNDER_XVFB", nullptr);
    ScopedEnv p("PATH", "/nonexistent");
    try {
      ensure_display(1, argv);
      FAIL() << "no exception";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("no display and no xvfb-run"), std::string::npos)
          << e.what();
    }
    EXPECT_EQ(std::getenv("MPM_UNDER_XVFB"), nullptr);
  }
}
