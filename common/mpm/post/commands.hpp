#pragma once
/// The subcommands of mpm-post that need no VTK (vtk and render: post/vtk/vtk_commands.hpp).
/// Each takes its command-line values as given (quantities and axes as text, parsed here so
/// that errors name the option) and returns the exit status: 0 done, 2 bad input or a damaged
/// or unfinished stream (the frames before the damage are still used), the run's status when it
/// ended unstable. Reports go to stdout (or the output file), messages to stderr. Throws
/// InputError/StreamError for bad input, IoError when an output cannot be written.
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "mpm/post/profile.hpp"

namespace mpm {

/// mpm-post summary: what a stream holds (frames, history, end status), as text or JSON.
struct SummaryArgs {
  std::string input = "-";  ///< stream ("-": stdin)
  bool json = false;        ///< print JSON
};
int post_summary(const SummaryArgs& args);

/// mpm-post history: the time histories as CSV.
struct HistoryArgs {
  std::string input = "-";           ///< stream ("-": stdin)
  std::string output = "-";          ///< CSV file ("-": stdout)
  std::vector<std::string> columns;  ///< history columns to print; empty: all
  int digits = 10;                   ///< significant digits of the values
};
int post_history(const HistoryArgs& args);

/// mpm-post scene: the scene a model or result stream holds (TOML, after --set overrides), so
/// that `mpm-post scene RESULT > scene.toml` gives back a scene mpm-prep reads.
struct SceneArgs {
  std::string input = "-";   ///< stream ("-": stdin)
  std::string output = "-";  ///< TOML file ("-": stdout)
};
int post_scene(const SceneArgs& args);

/// mpm-post particles: the particles of one frame as CSV, a column per component (x_0, x_1,
/// sigma_0 ... sigma_5).
struct ParticlesArgs {
  std::string input = "-";           ///< stream ("-": stdin)
  std::string output = "-";          ///< CSV file ("-": stdout)
  std::string frame = "last";        ///< frame index (0 = first) or "last"
  std::vector<std::string> columns;  ///< particle columns; empty: all
  int digits = 10;                   ///< significant digits of the values
};
int post_particles(const ParticlesArgs& args);

/// mpm-post taylor: final length L and foot diameter D of a bar against a wall (TaylorMeter).
struct TaylorArgs {
  std::string input = "-";  ///< stream ("-": stdin)
  std::string body;         ///< body name; empty: the first
  std::string axis;         ///< "x", "y" or "z"; empty: the body's longest extent
  std::string wall;         ///< wall position along the axis (length); empty: the domain face
  std::string expect_L;     ///< reference length to compare with; empty: none
  std::string expect_D;     ///< reference diameter to compare with; empty: none
  bool surface = false;     ///< measure the surface instead of the particle centres
  bool json = false;        ///< print JSON (SI units)
  std::string symmetry;     ///< mirror planes (option_symmetry); empty: the scene's
};
int post_taylor(const TaylorArgs& args);

/// mpm-post debris: front and width of a debris cloud behind a struck plate (DebrisMeter).
struct DebrisArgs {
  std::string input = "-";       ///< stream ("-": stdin)
  std::string time;              ///< the frame nearest this time; empty: the last
  std::string axis;              ///< impact axis "x", "y" or "z"; empty: the projectile's velocity
  std::string plane;             ///< reference plane (length); empty: the target's rear face
  std::string face = "rear";     ///< the face the front is measured from: "rear" or "impact"
  std::string target;            ///< target body; empty: the first body at rest
  std::string projectile;        ///< projectile body; empty: the fastest body
  std::string expect_front;      ///< reference front (length); empty: none
  std::string expect_width;      ///< reference width (length); empty: none
  std::string link;              ///< fragments' linking length; empty: the grid's cell size
  double percentile = 99.5;      ///< the headline front and width are this percentile, %
  std::size_t min_fragment = 1;  ///< only fragments of at least this many particles count
  bool escaped = false;          ///< also count the particles that left the domain (ESCP)
  bool json = false;             ///< print JSON (SI units)
  std::string symmetry;          ///< mirror planes (option_symmetry); empty: the scene's
};
int post_debris(const DebrisArgs& args);

/// mpm-post crater: depth and diameter of a target's crater (or hole), and how deep each body
/// went (CraterMeter), on the frame nearest a time or the last.
struct CraterArgs {
  std::string input = "-";  ///< stream ("-": stdin)
  std::string time;         ///< the frame nearest this time; empty: the last
  std::string target;       ///< target body; empty: the first body at rest
  std::string projectile;   ///< projectile body (the axis goes through it); empty: the fastest
  std::string axis;         ///< impact axis "x", "y" or "z"; empty: the projectile's velocity
  std::string symmetry;     ///< mirror planes (option_symmetry); empty: the scene's
  bool json = false;        ///< print JSON (SI units)
};
int post_crater(const CraterArgs& args);

/// mpm-post residual: a projectile's velocity through a target, its residual velocity, exit
/// angle and mass lost to failure (ResidualMeter), as text or JSON; the history as CSV.
struct ResidualArgs {
  std::string input = "-";  ///< stream ("-": stdin)
  std::string body;         ///< the projectile; empty: the fastest body at t = 0
  std::string target;       ///< the target; empty: every other body
  std::string output;       ///< CSV history file ("-": stdout); empty: none
  std::string symmetry;     ///< mirror planes (option_symmetry); empty: the scene's
  std::string plot;         ///< PNG chart of the history; empty: none
  bool json = false;        ///< print JSON (SI units)
};
struct ResidualResult;
/// Draws a residual history into a PNG file (mpm-post passes plot_residual_png of post/vtk).
using ResidualPlot = std::function<void(const ResidualResult&, const std::string& path)>;
/// Throws std::logic_error when args.plot is given and `plot` is empty.
int post_residual(const ResidualArgs& args, const ResidualPlot& plot = {});

/// mpm-post profile: a field along a line (make_profile) of one or more frames, CSV or JSON.
struct ProfileArgs {
  std::string input = "-";         ///< stream ("-": stdin)
  std::string output = "-";        ///< CSV or JSON file ("-": stdout)
  std::string component = "0";     ///< component name or index (component_index)
  std::string along = "x";         ///< the default line's direction "x", "y" or "z"
  std::string from, to;            ///< the line's ends (points); empty: along `along`
  std::string radius;              ///< leave out particles farther off (length); empty: none
  std::string body;                ///< only this body's particles; empty: all
  std::vector<std::string> times;  ///< the frames nearest these times
  std::vector<long> frames;        ///< frames of these indices; with no times either: the last
  ProfileOptions profile;          ///< field and bins as given; the rest is set from the above
  bool json = false;               ///< print JSON (SI units)
  bool grid = false;               ///< profile the field projected onto the run's grid nodes
  std::string weight = "volume";   ///< bins' means weighted by particle "volume" or "mass"
};
int post_profile(const ProfileArgs& args);

}  // namespace mpm
