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

std::string stream_producer(const std::string& path) {
  if (path == "-") return "";
  struct Stop {};  // thrown by the visitor at the first INFO record: nothing more is read
  std::string producer;
  StreamVisitor v;
  v.want_frames = false;
  v.info = [&](const std::string& text) {
    const std::string key = "tool = \"";
    const auto at = text.find(key);
    if (at != std::string::npos) {
      const auto end = text.find('"', at + key.size());
      if (end != std::string::npos) producer = text.substr(at + key.size(), end - at - key.size());
    }
    throw Stop{};
  };
  v.frame = [&](Frame&&) { throw Stop{}; };
  try {
    (void)read_stream(path, v);
  } catch (const Stop&) {
  }
  return producer;
}

void require_result(const std::string& path, const std::string& command) {
  if (stream_producer(path) == "mpm-prep")
    throw InputError(input_name(path),
                     "this is a model from mpm-prep, not a result: run mpm-run on it (mpm-run " +
                         path + " -o result.mpm), then mpm-post " + command + " on the result");
}

void check_written(std::FILE* out, const std::string& path) {
  if (std::ferror(out))
    throw IoError("cannot write '" + (path == "-" ? std::string("stdout") : path) +
                  "': " + std::strerror(errno));
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
  } else if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
    throw IoError(std::string("cannot write stdout: ") + std::strerror(errno));
  }
}

}  // namespace mpm
