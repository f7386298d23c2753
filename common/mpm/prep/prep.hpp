#pragma once
/// mpm-prep: scene file to model stream (particles, lattice, the scene with its domain made
/// explicit so that the model is self-contained).
#include <string>
#include <vector>

namespace mpm {

struct PrepOptions {
  std::string scene = "-";             ///< scene file, "-" for stdin
  std::string output = "-";            ///< model stream, "-" for stdout
  std::vector<std::string> overrides;  ///< --set key=value
  bool quiet = false;                  ///< no summary on stderr
  double max_memory = 0;  ///< bytes a model may need (--max-memory); 0: the machine's memory
};

/// Builds the model and writes it. Returns the exit status; throws InputError for bad input.
int prepare_model(const PrepOptions& options);

}  // namespace mpm
