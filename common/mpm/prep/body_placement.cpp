// Where a body is: its placement in the world and its mesh file (body_placement.hpp).
#include "mpm/prep/body_placement.hpp"

#include <Eigen/Geometry>
#include <filesystem>
#include <numbers>

#include "mpm/core/error.hpp"

namespace mpm {

Mat3 body_rotation(const BodySpec& body) {
  const double k = std::numbers::pi / 180.0;
  using Eigen::AngleAxisd;
  const Mat3 rx = AngleAxisd(k * body.rotate_deg.x(), Vec3::UnitX()).toRotationMatrix();
  const Mat3 ry = AngleAxisd(k * body.rotate_deg.y(), Vec3::UnitY()).toRotationMatrix();
  const Mat3 rz = AngleAxisd(k * body.rotate_deg.z(), Vec3::UnitZ()).toRotationMatrix();
  return rz * ry * rx;
}

Mat3 body_linear_map(const BodySpec& body) {
  return body_rotation(body) * body.scale.asDiagonal();
}

std::string body_where(const Scene& scene, const BodySpec& body, const std::string& field) {
  return where(scene.source, body.loc.line,
               "bodies." + body.name + (field.empty() ? "" : "." + field));
}

std::string resolve_mesh_path(const BodySpec& body, const Scene& scene) {
  const std::filesystem::path p(body.mesh_path);
  if (p.is_absolute() || scene.directory.empty()) return p.string();
  return (std::filesystem::path(scene.directory) / p).string();
}

}  // namespace mpm
