#pragma once
/// mpm-run: reads a model stream, runs the solver the scene asks for, writes a result stream.
#include <string>
#include <vector>

#include "mpm/core/progress.hpp"

namespace mpm {

struct RunOptions {
  std::string input = "-";             ///< model stream ("-": stdin)
  std::string output = "-";            ///< result stream ("-": stdout)
  int threads = 0;                     ///< OpenMP threads; 0: the OpenMP default
  std::vector<std::string> overrides;  ///< --set key=value
  bool stats = false;                  ///< print the kernel time table at the end
  std::string strategy = "colored";    ///< particle-to-grid scatter strategy
  bool deterministic = false;          ///< results independent of the thread count
  ProgressMode progress = ProgressMode::Auto;
  std::string restart;    ///< result stream to continue from its last checkpoint ("": none)
  double max_memory = 0;  ///< bytes the run may need (--max-memory); 0: the machine's memory
};

/// Runs a model to its end time (or, with `restart`, continues a result stream from its last
/// checkpoint: written to `output`, which may be that stream itself). Returns the exit status
/// (ExitStatus); errors in the input throw InputError/StreamError, write failures IoError.
int run_model(const RunOptions& options);

/// Face names in BoundarySpec order: x_min, x_max, y_min, y_max, z_min, z_max.
const char* face_name(int face);

}  // namespace mpm
