#include "mpm/core/cli.hpp"

#include <unistd.h>

#include <cctype>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <new>
#include <string>

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

double machine_memory() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? double(pages) * double(page) : 0.0;
}

double parse_memory_size(const std::string& text, const std::string& option) {
  std::size_t used = 0;
  double v = -1;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  std::string unit = text.substr(used);
  for (char& c : unit) c = char(std::toupper(static_cast<unsigned char>(c)));
  if (unit.size() > 1 && (unit.ends_with("IB") || unit.ends_with("B")))
    unit.erase(unit.size() - (unit.ends_with("IB") ? 2 : 1));
  const std::string units = "KMGT";
  double factor = 1;
  if (unit == "B") unit.clear();
  if (unit.size() == 1 && units.find(unit[0]) != std::string::npos)
    factor = std::ldexp(1.0, 10 * (1 + int(units.find(unit[0]))));
  else if (!unit.empty())
    used = 0;
  if (used == 0 || !(v > 0) || !std::isfinite(v))
    throw InputError(option,
                     "expected a memory size such as 16G, 512M or 2000000000 (bytes; K, "
                     "M, G, T are powers of 1024), got '" +
                         text + "'");
  return v * factor;
}

std::string format_bytes(double bytes) {
  static const char* names[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB"};
  int k = 0;
  double v = bytes;
  while (v >= 1024 && k < 5) v /= 1024, ++k;
  char b[48];
  if (v >= 1024)
    std::snprintf(b, sizeof b, "%.3g bytes", bytes);
  else
    std::snprintf(b, sizeof b, k == 0 ? "%.0f %s" : "%.3g %s", v, names[k]);
  return b;
}

void ignore_sigpipe() {
  std::signal(SIGPIPE, SIG_IGN);
}

}  // namespace mpm
