#pragma once
/// Profiles of a particle field along a line (mpm-post profile): the particles within a
/// distance of the line, their position s along it and the field's value, one row per
/// particle or averaged in bins. For stress waves in rods (V1), shocks along an axis, ...
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "mpm/core/types.hpp"
#include "mpm/stream/stream.hpp"

namespace mpm {

/// What a particle weighs in a bin's mean: its volume m / rho (a mean over space), or its
/// mass m (a mean over material: momentum-like, as the grid transfers weigh it).
enum class ProfileWeight { Volume, Mass };

struct ProfileOptions {
  std::string field = "sigma";   ///< a column, or "pressure", "von_mises", "speed" (derived)
  int component = 0;             ///< of a vector or tensor column (sigma in Voigt order xx yy zz
                                 ///< yz xz xy); -1: the magnitude
  std::optional<Vec3> from, to;  ///< the line, m; default: along `axis` over the particles' extent,
                                 ///< through their centroid
  int axis = 0;                  ///< 0, 1, 2: the default line's direction
  double radius =
      std::numeric_limits<double>::infinity();  ///< m: particles farther off are left out
  int body = -1;                                ///< only this body's particles; -1: all
  int bins = 0;  ///< 0: one row per particle; else equal bins over the line
  ProfileWeight weight = ProfileWeight::Volume;  ///< particles' weights (on the grid: mass)
  /// On the grid: the field projected onto the nodes of the run's uniform grid (cell size
  /// `cell`, a node at `origin`) with the linear shape functions, weighted by particle mass as
  /// the solver's particle-to-grid transfer weights momentum; the rows are then the nodes within
  /// `radius` of the line (the way MPM papers graph stresses "on the mesh").
  bool on_grid = false;
  double cell = 0;             ///< m
  Vec3 origin = Vec3::Zero();  ///< m
};

/// One profile. Per particle (bins = 0): s, value, weight (sorted by s). In bins: s is the bin
/// centre, value the weighted mean, min and max the extremes, count the particles.
/// Weights are particle volumes m / rho (m^3, per metre in 2D, per radian in axisymmetry) when
/// the frame holds m and rho, else 1; with ProfileWeight::Mass particle masses m (kg). On the
/// grid the rows are nodes and the weights their masses (kg; 1 a particle without the column
/// m).
struct Profile {
  double time = 0;  ///< s
  Vec3 from = Vec3::Zero(), to = Vec3::Zero();
  std::string unit;
  std::vector<double> s, value, weight, min, max;
  std::vector<std::size_t> count;
};

/// The profile of a frame (dim 2 or 3). Throws InputError naming the available fields for an
/// unknown field or a component out of range, or when no particle lies near the line.
Profile make_profile(const Frame& frame, int dim, const ProfileOptions& options);

/// Component index of a name: "xx".."xy" for Voigt tensors, "x", "y", "z" for vectors, or a
/// number; -1 for "magnitude". Throws InputError.
int component_index(const std::string& name);

}  // namespace mpm
