#pragma once
/// What mpm-post extracts from result streams.
#include <optional>
#include <string>
#include <vector>

#include "mpm/scene.hpp"
#include "mpm/stream.hpp"

namespace mpm {

/// Taylor bar measures.
struct TaylorOptions {
  int axis = -1;             ///< bar axis (0, 1, 2); -1: the body's longest initial extent
  std::optional<double> wall;///< wall position along the axis, m; default: the constrained domain face
  std::string body;          ///< body name; empty: the first body
  bool surface = false;      ///< add half a particle spacing at each free end (else particle centres)
};

struct TaylorResult {
  double time = 0;      ///< s, of the measured frame
  double L = 0, D = 0;  ///< final length and foot diameter, m
  double L0 = 0, D0 = 0;///< the same measures on the first frame, m
  int axis = 2;
  double wall = 0;      ///< m
  double spacing = 0;   ///< initial particle spacing of the body, m
  std::size_t particles = 0;
  std::string measure;  ///< "centres" or "surface"
};

/// Measures a bar standing on a wall: L is the largest distance of a particle from the wall
/// along the axis; D twice the largest distance of a particle from the bar's axis (through the
/// mass centre of the particles in the plane across it). "surface" adds half a spacing to L
/// and a whole spacing to D. Throws InputError when the body or the wall cannot be found.
class TaylorMeter {
 public:
  TaylorMeter(const Scene& scene, const TaylorOptions& options);
  /// Measures one frame.
  TaylorResult measure(const Frame& frame) const;

 private:
  Scene scene_;
  TaylorOptions opt_;
  int body_ = 0;
};

}  // namespace mpm
