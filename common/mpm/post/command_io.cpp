// What mpm-post's subcommands share around a result stream.
#include "mpm/post/command_io.hpp"

#include <cerrno>
#include <cstring>

#include "mpm/core/error.hpp"

namespace mpm {

std::string input_name(const std::string& path) {
  return path == "-" ? "stdin" : path;
}

Scene scene_of(const std::string& text, const std::string& path) {
  if (text.empty()) throw StreamError(input_name(path), "the stream holds no scene record");
  return parse_scene(text, input_name(path) + " (scene)", "", {});
}

int conclude(const std::string& path, const StreamSummary& s, std::size_t frames_used) {
  if (!s.damage.empty()) {
    std::fprintf(stderr, "mpm-post: error: %s; used the %zu frame(s) before it\n", s.damage.c_str(),
                 frames_used);
    return kExitBadInput;
  }
  if (!s.ended) {
    std::fprintf(stderr,
                 "mpm-post: error: %s: the stream ends without an end record: its producer stopped "
                 "before finishing (killed, or still running); used the %zu frame(s) it holds\n",
                 input_name(path).c_str(), frames_used);
    return kExitBadInput;
  }
  if (s.end_status != 0) {
    std::fprintf(stderr, "mpm-post: warning: the run ended with status %d: %s\n", s.end_status,
                 s.end_message.c_str());
    return s.end_status;
  }
  return kExitOk;
}

std::FILE* open_output(const std::string& path) {
  std::FILE* f = path == "-" ? stdout : std::fopen(path.c_str(), "w");
  if (!f) throw IoError("cannot write '" + path + "': " + std::strerror(errno));
  return f;
}

void close_output(std::FILE* out, const std::string& path) {
  if (out != stdout) {
    if (std::fclose(out) != 0)
      throw IoError("cannot write '" + path + "': " + std::strerror(errno));
  } else {
    std::fflush(stdout);
  }
}

}  // namespace mpm
