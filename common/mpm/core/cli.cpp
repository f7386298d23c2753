#include "mpm/core/cli.hpp"

#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <new>

#include "mpm/core/error.hpp"

namespace mpm {

int guarded_main(const char* tool, const std::function<int()>& body) {
  try {
    return body();
  } catch (const InputError& e) {
    std::fprintf(stderr, "%s: error: %s\n", tool, e.what());
    return kExitBadInput;
  } catch (const IoError& e) {
    std::fprintf(stderr, "%s: error: %s\n", tool, e.what());
    return kExitIo;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "%s: error: out of memory\n", tool);
    return kExitInternal;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: internal error: %s\n", tool, e.what());
    return kExitInternal;
  }
}

void refuse_terminal_output(const std::string& path, const char* what) {
  if (path == "-" && isatty(1))
    throw InputError("-o", std::string("standard output is a terminal; ") + what +
                               " is binary: pipe it into the next tool or write it with -o FILE");
}

void check_output_file(const std::string& output, const std::vector<std::string>& inputs) {
  if (output == "-") return;
  std::error_code ec;
  if (std::filesystem::is_directory(output, ec))
    throw InputError("-o " + output, "is a directory; expected the name of a file to write");
  for (const auto& input : inputs) {
    if (input == "-") continue;
    if (std::filesystem::equivalent(output, input, ec) && !ec)
      throw InputError("-o " + output,
                       "is the input file '" + input +
                           "'; writing it would destroy the input: choose another output file");
  }
}

void ignore_sigpipe() {
  std::signal(SIGPIPE, SIG_IGN);
}

}  // namespace mpm
