#pragma once
/// What mpm-post's subcommands share around a result stream: the input's name in messages,
/// the scene record, the exit status after reading, output files.
#include <cstddef>
#include <cstdio>
#include <string>

#include "mpm/scene/scene.hpp"
#include "mpm/stream/stream.hpp"

namespace mpm {

/// The input's name in messages: "stdin" for "-", else the path.
std::string input_name(const std::string& path);

/// The scene of a stream's scene record `text`. Throws StreamError when the stream has none,
/// InputError when it does not parse.
Scene scene_of(const std::string& text, const std::string& path);

/// What every subcommand says after reading: an error on damage or a stream without an end
/// record (exit 2, naming the `frames_used`), a warning when the run ended with a failure (its
/// status); else 0. Messages go to stderr.
int conclude(const std::string& path, const StreamSummary& summary, std::size_t frames_used);

/// The tool that wrote the stream file `path`, as its first INFO record names it ("mpm-prep"
/// for a model, "mpm-run" for a result); empty for stdin (not read twice) or when unknown.
/// Reads only the records before the first frame.
std::string stream_producer(const std::string& path);

/// Throws InputError when `path` is a model from mpm-prep: `command` measures a result, so
/// the message says to run mpm-run on it.
void require_result(const std::string& path, const std::string& command);

/// Throws IoError when a write to `out` failed (a closed pipe, a full disk): writers call it
/// once a row, so a closed pipe stops the command at its first failed write.
void check_written(std::FILE* out, const std::string& path);

/// An output of a subcommand: stdout for "-", else the file opened for writing. Throws IoError.
std::FILE* open_output(const std::string& path);

/// Closes an output of open_output (stdout is flushed). Throws IoError when the file cannot be
/// written.
void close_output(std::FILE* out, const std::string& path);

}  // namespace mpm
