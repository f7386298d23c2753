#pragma once
/// Errors and exit statuses shared by the three tools.
#include <stdexcept>
#include <string>

namespace mpm {

/// Exit statuses of mpm-prep, mpm-run and mpm-post (documented in docs/format.md).
enum ExitStatus : int {
  kExitOk = 0,
  kExitInternal = 1,    ///< a bug or an unexpected system failure
  kExitBadInput = 2,    ///< the user's input (scene, option, mesh, stream) is wrong
  kExitUnstable = 3,    ///< the run went unstable; frames written so far stay valid
  kExitIo = 4,          ///< writing failed (disk full, closed pipe)
  kExitLeftDomain = 5,  ///< a particle left the domain with solver.on_exit = "stop"; frames valid
};

/// A mistake in the user's input. what() reads "where: message", where names the file, the
/// line and the key when they are known (e.g. "scene.toml:12: materials.cu.density").
class InputError : public std::runtime_error {
 public:
  InputError(const std::string& where, const std::string& message)
      : std::runtime_error(where.empty() ? message : where + ": " + message),
        where_(where),
        message_(message) {}
  const std::string& where() const { return where_; }
  const std::string& message() const { return message_; }

 private:
  std::string where_, message_;
};

/// A stream (model or result file) that is truncated, corrupted or of the wrong version.
/// Frames read before the damage stay usable; the reader says how many there were.
class StreamError : public InputError {
 public:
  using InputError::InputError;
};

/// Writing failed (disk full, the reader of a pipe went away).
class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Formats "file:line: key" for an error location; parts that are empty or zero are left out.
std::string where(const std::string& file, int line, const std::string& key);

}  // namespace mpm
