// mpm-post residual on a result stream written here with the library's writer: a rod of
// particles decelerating at a known rate along its initial direction (30 degrees off -z) and
// drifting sideways at a known rate, through a slab normal to z, its nose row failing on the
// way. Every frame's velocity is the exact kinematics, so the measure must give the residual
// and exit velocities, the exit frame, the angle and the mass lost to round-off. A half model
// (mirror plane x = 0) with particles spreading along x: the whole body's x velocity is zero.
#include <gtest/gtest.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "mpm/post/residual.hpp"
#include "mpm/scene/particles.hpp"
#include "mpm/stream/stream.hpp"
#include "run_command.hpp"

namespace mpm {
namespace {

using testing::json_value;
using testing::run;
using testing::temp_dir;

const double kPi = std::numbers::pi;
const double kV0 = 575, kDecel = 1e6, kDrift = 1e5;  // m/s, m/s^2 along d0, m/s^2 along x
const double kMass = 1e-4, kDt = 10e-6;              // kg a particle, s between frames
const int kFrames = 41;                              // 0 .. 400 us
const Vec3 kD0(0, -0.5, -std::sqrt(3.0) / 2);        // 30 degrees off -z, towards -y

/// The scene as mpm-post reads it: the rod (3 x 3 x 20 points, 1 mm apart, z = 1 .. 20 mm)
/// and the slab (z = -10 .. 0 mm), both boxes; a slip face x_min = 0 through both in the half
/// model.
std::string scene_text(bool half) {
  return std::string(R"(
[materials.steel]
density = 7850
youngs_modulus = 2e11
poisson_ratio = 0.3

[[bodies]]
name = "plate"
material = "steel"
shape = "box"
size = "40 40 11 mm"
translate = "0 0 -5 mm"

[[bodies]]
name = "rod"
material = "steel"
shape = "box"
size = "3 3 20 mm"
translate = "0 0 10.5 mm"
velocity = "0 -287.5 -497.9646071760522 m/s"

[grid]
cell_size = "1 mm"
domain = { min = ")") +
         (half ? "0" : "-30") + R"( -30 -30 mm", max = "30 30 30 mm" }

[boundary]
x_min = ")" +
         (half ? "slip" : "free") +
         R"("

[solver]
end_time = "400 us"
)";
}

/// The rod's displacement at time t: (v0 t - a t^2 / 2) d0 + (w t^2 / 2) x.
Vec3 displacement(double t) {
  return (kV0 * t - 0.5 * kDecel * t * t) * kD0 + 0.5 * kDrift * t * t * Vec3::UnitX();
}
Vec3 velocity(double t) {
  return (kV0 - kDecel * t) * kD0 + kDrift * t * Vec3::UnitX();
}
/// The nose row (the lowest z) fails at 50 us and later.
bool nose_failed(double t) {
  return t >= 50e-6 - 1e-12;
}

/// Frame k. Half model: only x >= 0 (x = 0 and 1 mm columns at 0.5, 1.5 mm), each particle
/// also spreading along x at 40 m/s per mm of x (a whole body's x momentum: zero).
Frame frame(int k, bool half) {
  const double t = k * kDt;
  struct P {
    Vec3 x, v;
    std::uint8_t body, failed;
  };
  std::vector<P> ps;
  const std::vector<double> xs =
      half ? std::vector<double>{0.5e-3, 1.5e-3} : std::vector<double>{-1e-3, 0, 1e-3};
  for (double x : xs)
    for (double y : {-10e-3, 0.0, 10e-3})
      for (double z : {-10e-3, -5e-3, 0.0})  // the slab, wobbling
        ps.push_back({Vec3(x, y, z), Vec3(3, -2, 1), 0, 0});
  for (double x : xs)
    for (double y : {-1e-3, 0.0, 1e-3})
      for (int iz = 0; iz < 20; ++iz) {
        const bool failed = iz == 0 && nose_failed(t);
        const Vec3 spread = half ? Vec3(40e3 * x, 0, 0) : Vec3::Zero();
        ps.push_back({Vec3(x, y, (iz + 1) * 1e-3) + displacement(t),
                      failed ? Vec3(-300, 200, 100) : Vec3(velocity(t) + spread), 1,
                      std::uint8_t(failed)});
      }
  Frame f;
  f.step = k;
  f.time = t;
  f.columns.add({col::x, ScalarType::F64, 3, "m"});
  f.columns.add({col::v, ScalarType::F64, 3, "m/s"});
  f.columns.add({col::m, ScalarType::F64, 1, "kg"});
  f.columns.add({col::body, ScalarType::U8, 1, "-"});
  f.columns.add({col::failed, ScalarType::U8, 1, "-"});
  f.columns.resize(ps.size());
  for (std::size_t i = 0; i < ps.size(); ++i) {
    f.columns.get<Vec3>(col::x)[i] = ps[i].x;
    f.columns.get<Vec3>(col::v)[i] = ps[i].v;
    f.columns.get<double>(col::m)[i] = kMass;
    f.columns.get<std::uint8_t>(col::body)[i] = ps[i].body;
    f.columns.get<std::uint8_t>(col::failed)[i] = ps[i].failed;
  }
  return f;
}

/// The first frame at which the rod's top (z = 20 mm at t = 0) is below the slab's lowest
/// particle centres (z = -10 mm): the displacement along z, -(v0 t - a t^2/2) cos 30, reaches
/// -30 mm at the root t_x of a t^2/2 - v0 t + 30 mm / cos 30 = 0.
double exit_time() {
  const double c = 30e-3 / std::cos(kPi / 6);
  const double t_x = (kV0 - std::sqrt(kV0 * kV0 - 2 * kDecel * c)) / kDecel;
  return std::ceil(t_x / kDt + 1e-9) * kDt;
}

void write_stream(const std::string& path, bool half) {
  StreamWriter w(path);
  w.write_text(RecordType::Info, "tool = \"mpm-run\"\n");
  w.write_text(RecordType::Scene, scene_text(half));
  for (int k = 0; k < kFrames; ++k) w.write_frame(frame(k, half));
  w.write_end(0, "");
  w.close();
}

/// The angle between v and d0, degrees.
double angle(const Vec3& v) {
  return std::acos(v.dot(kD0) / v.norm()) * 180 / kPi;
}

TEST(CliResidual, ResidualExitVelocityAngleAndMassLostOnAConstructedStream) {
  const auto dir = temp_dir("residual");
  const std::string stream = (dir / "result.mpm").string();
  write_stream(stream, false);
  const auto r = run(testing::post + " residual " + stream + " --body rod --json -o " +
                         (dir / "history.csv").string(),
                     dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string& j = r.out;
  // Round-off: velocities are sums of 171 equal terms over their mass (relative 1e-13); the
  // JSON prints 10 digits, so compare to 1e-9 relative.
  const double t_end = (kFrames - 1) * kDt, t_x = exit_time();
  EXPECT_NEAR(t_x, 70e-6, 1e-12);  // the kinematics chosen: t_x = 63.6 us, the frame after
  EXPECT_NEAR(json_value(j, "initial_speed"), kV0, 1e-9 * kV0);
  EXPECT_NEAR(json_value(j, "residual_velocity"), velocity(t_end).norm(), 1e-6);
  EXPECT_NEAR(json_value(j, "exit_velocity"), velocity(t_x).norm(), 1e-6);
  EXPECT_NEAR(json_value(j, "exit_angle_deg"), angle(velocity(t_x)), 1e-7);
  EXPECT_NEAR(json_value(j, "time"), t_x, 1e-15);  // the exit object's time comes first
  EXPECT_NEAR(json_value(j, "far_face"), 10e-3, 1e-15);
  EXPECT_NEAR(json_value(j, "initial_mass"), 180 * kMass, 1e-15);
  EXPECT_NEAR(json_value(j, "mass_lost"), 9 * kMass, 1e-15);
  EXPECT_NEAR(json_value(j, "mass_lost_fraction"), 0.05, 1e-12);
  EXPECT_NE(j.find("\"zero_components\": \"\""), std::string::npos) << j;
  // The history: a row per frame; the along component at 200 us.
  const std::string csv = testing::slurp(dir / "history.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), kFrames + 1);
  EXPECT_NE(csv.find("time_s,v_x,v_y,v_z,v_along,speed,angle_deg"), std::string::npos);
  char row[64];
  std::snprintf(row, sizeof row, "\n0.0002,%.10g,", velocity(200e-6).x());
  EXPECT_NE(csv.find(row), std::string::npos) << csv;

  // Text: the exit frame and the end.
  const auto t = run(testing::post + " residual " + stream, dir);
  ASSERT_EQ(t.status, 0) << t.err;
  EXPECT_NE(t.out.find("Residual velocity of 'rod' through 'plate'"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("tail left the target at t = 70 us"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("mass lost to failure: 0.9 g of 18 g (5%)"), std::string::npos) << t.out;
}

// --plot: a 1200 x 800 PNG chart, drawn off-screen (under xvfb-run without a display), with
// the blue speed line (31, 119, 180) running from the top left (575 m/s at t = 0) to the bottom
// right (179.5 m/s at 400 us): its pixels in the left tenth lie above those in the right tenth.
TEST(CliResidual, PlotIsAPngOfTheHistory) {
  const auto dir = temp_dir("residual_plot");
  const std::string stream = (dir / "result.mpm").string();
  write_stream(stream, false);
  const std::string png = (dir / "residual.png").string();
  const auto r =
      run("env -u DISPLAY " + testing::post + " residual " + stream + " --plot " + png, dir);
  ASSERT_EQ(r.status, 0) << r.err;
  vtkNew<vtkPNGReader> reader;
  reader->SetFileName(png.c_str());
  reader->Update();
  vtkImageData* img = reader->GetOutput();
  int dims[3];
  img->GetDimensions(dims);
  ASSERT_EQ(dims[0], 1200);
  ASSERT_EQ(dims[1], 800);
  double left = 0, right = 0;  // mean row (from the bottom) of the blue pixels
  int n_left = 0, n_right = 0;
  for (int y = 0; y < dims[1]; ++y)
    for (int x = 0; x < dims[0]; ++x) {
      const auto* px = static_cast<unsigned char*>(img->GetScalarPointer(x, y, 0));
      if (std::abs(px[0] - 31) > 30 || std::abs(px[1] - 119) > 30 || std::abs(px[2] - 180) > 30)
        continue;
      if (x < dims[0] / 10) left += y, ++n_left;
      if (x > 9 * dims[0] / 10) right += y, ++n_right;
    }
  ASSERT_GT(n_left, 0);
  ASSERT_GT(n_right, 0);
  EXPECT_GT(left / n_left, right / n_right + 0.4 * dims[1]);
}

TEST(CliResidual, UnknownBodyExitsTwoNamingItAndTheKnownOnes) {
  const auto dir = temp_dir("residual_bad");
  const std::string stream = (dir / "result.mpm").string();
  write_stream(stream, false);
  auto r = run(testing::post + " residual " + stream + " --body bullet", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--body: no body named 'bullet' in the scene (known: plate, rod)"),
            std::string::npos)
      << r.err;
  r = run(testing::post + " residual " + stream + " --body rod --target rod", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--target"), std::string::npos) << r.err;
}

// Half model: mirror plane x = 0 from the scene's slip face. The particles spread along +x in
// the model; the whole body does not move along x, so v_x is reported zero and said so, the
// along-d0 component is the kinematics' exactly, and the masses are the whole body's.
TEST(CliResidual, HalfModelZeroesTheComponentNormalToTheMirrorPlane) {
  const Scene scene = parse_scene(scene_text(true), "scene.toml", "", {});
  ResidualOptions opt;
  opt.body = "rod";
  ResidualMeter meter(scene, frame(0, true), opt);
  for (int k = 0; k < kFrames; ++k) meter.add(frame(k, true));
  const ResidualResult& r = meter.result();
  ASSERT_EQ(r.symmetry.planes.size(), 1u);
  EXPECT_EQ(r.zero_components, "x");
  EXPECT_EQ(r.targets, std::vector<std::string>{"plate"});
  const double t_end = (kFrames - 1) * kDt;
  EXPECT_EQ(r.end().v.x(), 0.0);
  EXPECT_NEAR(r.end().v_along, kV0 - kDecel * t_end, 1e-10 * kV0);
  EXPECT_NEAR(r.end().angle, 0.0, 1e-6);
  EXPECT_NEAR(r.initial_mass, 2 * 120 * kMass, 1e-15);  // 120 particles in the half, mirrored
  EXPECT_NEAR(r.end().failed_mass, 2 * 6 * kMass, 1e-15);
  ASSERT_TRUE(r.exit.has_value());
  EXPECT_NEAR(r.exit->time, exit_time(), 1e-15);
}

}  // namespace
}  // namespace mpm
