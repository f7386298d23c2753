#pragma once
/// What mpm-post extracts from result streams.
#include <optional>
#include <string>
#include <vector>

#include "mpm/post/symmetry.hpp"
#include "mpm/scene/scene.hpp"
#include "mpm/stream/stream.hpp"

namespace mpm {

/// Taylor bar measures.
struct TaylorOptions {
  int axis = -1;  ///< bar axis (0, 1, 2); -1: the body's longest initial extent
  std::optional<double>
      wall;              ///< wall position along the axis, m; default: the constrained domain face
  std::string body;      ///< body name; empty: the first body
  bool surface = false;  ///< add half a particle spacing at each free end (else particle centres)
  std::optional<Symmetry> symmetry;  ///< the model's mirror planes; none: the scene's
};

struct TaylorResult {
  double time = 0;              ///< s, of the measured frame
  double L = 0, D = 0;          ///< final length and foot diameter, m
  double D_min = 0, D_max = 0;  ///< narrowest and widest caliper width across the axis, m
  double D_radius = 0;          ///< twice the largest distance from the axis, m (the old D)
  double L0 = 0, D0 = 0;        ///< the same measures on the first frame, m
  int axis = 2;
  double wall = 0;            ///< m
  double spacing = 0;         ///< initial particle spacing of the body, m
  std::size_t particles = 0;  ///< of the model (the whole bar has symmetry.images() as many)
  Symmetry symmetry;          ///< what the whole bar was made of
  std::string measure;        ///< "centres" or "surface"
};

/// Measures a bar standing on a wall: L is the largest distance of a particle from the wall
/// along the axis. D is the foot's diameter as calipers give it: in 3D the width of the
/// particles' projection on the plane across the axis averaged over all directions (the
/// hull's perimeter / pi), with the narrowest and widest widths beside it; in plane strain the
/// width across the axis; in axisymmetry twice the largest radius. (A Cartesian grid leaves
/// the foot slightly four-fold, so twice the largest distance from the axis, D_radius, is an
/// upper bound set by one particle.) All of these are of the whole bar: the model's particles
/// and their images in the symmetry's mirror planes (a quarter or half model). "surface" adds half
/// a spacing to L and a whole spacing to the diameters. Throws InputError when the body or the wall
/// cannot be found.
class TaylorMeter {
 public:
  TaylorMeter(const Scene& scene, const TaylorOptions& options);
  /// Measures one frame.
  TaylorResult measure(const Frame& frame) const;

 private:
  Scene scene_;
  TaylorOptions opt_;
  Symmetry symmetry_;
  int body_ = 0;
};

/// The face of the struck plate the front is measured from.
enum class DebrisFace { Rear, Impact };

/// Debris cloud measures (hypervelocity impact).
struct DebrisOptions {
  int axis = -1;                ///< impact axis 0, 1, 2; -1: the projectile's velocity direction
  std::optional<double> plane;  ///< reference plane along the axis, m; default: target's rear face
  std::string target;           ///< target body; empty: the first body at rest at t = 0
  std::string projectile;       ///< projectile body; empty: the fastest body at t = 0
  double percentile = 99.5;     ///< the headline front and width are this percentile
  /// Fragments: cloud particles closer than `link` belong to one fragment (friends of
  /// friends); only fragments of at least `min_fragment` particles count. 0: the grid's cell
  /// size (particles closer than a cell share grid nodes, so the grid moves them together).
  double link = 0;
  std::size_t min_fragment = 1;      ///< 1: every cloud particle counts
  std::optional<Symmetry> symmetry;  ///< the model's mirror planes; none: the scene's
  /// The front is the distance from this face of the target (its surface at t = 0: outermost
  /// particle centres plus half a spacing); the cloud is what lies behind `plane` either way.
  DebrisFace face = DebrisFace::Rear;
};

struct DebrisResult {
  double time = 0;
  int axis = 0;
  int direction = 1;               ///< +1 or -1: the impact runs along +axis or -axis
  double plane = 0;                ///< reference plane position along the axis, m
  Vec3 axis_point = Vec3::Zero();  ///< a point of the impact axis (projectile's initial centre)
  /// Particles of the whole body (with mirror images) behind the plane; the model's particles.
  std::size_t cloud = 0, total = 0;
  Symmetry symmetry;  ///< what the whole body was made of
  double percentile = 99.5;
  /// Distances behind the plane (front) and twice the distances from the axis (width), m:
  /// the maximum, the 99th, 99.5th and 99.9th percentiles, and the headline percentile.
  double front_max = 0, front_p99 = 0, front_p995 = 0, front_p999 = 0, front = 0;
  double width_max = 0, width_p99 = 0, width_p995 = 0, width_p999 = 0, width = 0;
  /// Fragments of the cloud at linking length `link` (m): how many, how many of one particle,
  /// the particles of the largest; `counted` cloud particles lie in fragments of at least
  /// `min_fragment` particles, and the distances above are theirs.
  double link = 0;
  std::size_t min_fragment = 1, fragments = 0, singles = 0, largest = 0, counted = 0;
  /// The percentiles are of the counted particles' mass (their masses differ: an axisymmetric
  /// model, where a particle stands for a ring of mass proportional to its radius, or bodies of
  /// different spacings), else of their number (equal masses, or frames without masses).
  bool by_mass = false;
  /// The face the front is measured from, and its position along the axis, m.
  DebrisFace face = DebrisFace::Rear;
  double face_plane = 0;
};

/// Fragments of a point set, friends of friends: points closer than `link` are in one
/// fragment. Returns, for each point, the number of points of its fragment.
std::vector<std::size_t> fragment_sizes(const std::vector<Vec3>& points, double link);

/// Measures debris clouds: set up from the first frame (axis, plane), then measure any frame.
/// The cloud is every particle downstream of the plane (the target's rear face, at the surface:
/// its outermost particle centres plus half a spacing). Front: distance behind the plane along
/// the impact direction; width: twice the distance from the impact axis. Percentiles are of the
/// cloud's mass (by number when all masses are equal: a model of one spacing). In an
/// axisymmetric scene the impact axis is the axis of revolution y, the width twice the radius
/// x, and a particle (a ring) weighs its mass per radian. A quarter or half model is measured
/// as the whole: its particles and their images in the symmetry's mirror planes (the fragments
/// too: one that lies across a plane is one fragment). Throws InputError.
class DebrisMeter {
 public:
  DebrisMeter(const Scene& scene, const Frame& first, const DebrisOptions& options);
  DebrisResult measure(const Frame& frame) const;

 private:
  DebrisOptions opt_;
  Symmetry symmetry_;
  int axis_ = 0, direction_ = 1;
  double plane_ = 0;
  double face_plane_ = 0;  ///< the plane the front is measured from
  Vec3 point_ = Vec3::Zero();
  int dim_ = 3;
  bool axisymmetric_ = false;
  double link_ = 0;
};

}  // namespace mpm
