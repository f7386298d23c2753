#pragma once
/// The symmetry of a model: which mirror planes make the whole body out of a quarter or half
/// model, so that the measures (taylor, debris, crater, and a coming residual velocity) report
/// the whole body's. A slip wall on a domain face that passes through a body is a mirror plane
/// (the wall keeps the normal velocity zero and leaves the tangential free, as the mirror image
/// would); an axisymmetric model is a solid of revolution.
#include <cstddef>
#include <string>
#include <vector>

#include "mpm/core/types.hpp"
#include "mpm/post/json.hpp"
#include "mpm/scene/scene.hpp"
#include "mpm/stream/stream.hpp"

namespace mpm {

/// A mirror plane normal to a coordinate axis.
struct MirrorPlane {
  int axis = 0;         ///< 0, 1, 2: the plane is x_axis = position
  double position = 0;  ///< m
};

/// Where a Symmetry came from, for the reports.
enum class SymmetrySource { None, Scene, Option };

struct Symmetry {
  std::vector<MirrorPlane> planes;  ///< at most one per axis, in axis order
  bool axisymmetric = false;        ///< 2D: x is the radius, y the axis of revolution
  SymmetrySource source = SymmetrySource::None;
  std::string reason;  ///< why the planes are there, e.g. "slip faces through body 'bar'"

  /// Images of each particle in the whole body: 2^planes (the particle itself is image 0).
  int images() const { return 1 << planes.size(); }
  /// Image k (0 .. images() - 1) of a point: reflected across the planes whose bit is set in k.
  Vec3 point_image(const Vec3& x, int k) const;
  /// Image k of a vector (velocity, momentum): the components normal to the reflected planes
  /// change sign.
  Vec3 vector_image(const Vec3& v, int k) const;
  /// One line for the reports: what the whole body is made of, e.g. "whole body from mirror
  /// planes x = 0 mm, y = 0 mm (slip faces through body 'bar'; 4 images of each particle)".
  std::string describe() const;
};

/// The symmetry a scene declares: its slip domain faces that pass through a body's shape
/// (boxes, cylinders and spheres: exactly; meshes are not known to mpm-post, give --symmetry),
/// and the axisymmetric flag. The axis face x_min of an axisymmetric scene is no plane.
Symmetry scene_symmetry(const Scene& scene);

/// The --symmetry option: "none" (measure the model as it is), or planes such as
/// "x = 0, y = 0 mm" (a length each, plain numbers in m; commas between planes),
/// overriding the scene's. An axisymmetric scene stays axisymmetric. Throws InputError naming
/// `option`.
Symmetry option_symmetry(const std::string& text, const Scene& scene, const std::string& option);

/// The symmetry to measure with: option_symmetry when `text` is not empty, else the scene's.
Symmetry measure_symmetry(const std::string& text, const Scene& scene);

/// The particles of a frame unfolded into the whole body: each selected particle and its
/// mirror images. `source[j]` is the frame's particle of entry j and `image[j]` its image
/// index (for Symmetry::vector_image of its vector columns).
struct WholeBody {
  std::vector<Vec3> x;              ///< positions, m (z = 0 in 2D)
  std::vector<double> m;            ///< masses, kg (1 each when the frame has no masses)
  std::vector<std::size_t> source;  ///< index of the particle in the frame
  std::vector<int> image;           ///< image index
  std::size_t particles = 0;        ///< particles of the model selected (before the images)
};

/// Unfolds the particles of `frame` whose body is in `bodies` (all particles when empty).
/// Throws InputError when the frame lacks the column x (or body, when bodies are chosen).
WholeBody unfold(const Frame& frame, int dimension, const Symmetry& symmetry,
                 const std::vector<int>& bodies);

/// The symmetry as a JSON object (the value after JsonWriter::key("symmetry")): planes, source,
/// axisymmetric, images.
void write_symmetry_json(JsonWriter& j, const Symmetry& symmetry);

}  // namespace mpm
