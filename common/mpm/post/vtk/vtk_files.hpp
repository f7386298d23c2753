#pragma once
/// Writing files with VTK (internal to mpm_vtk): errors collected instead of printed, files
/// written under a temporary name and committed, unstructured grids as .vtu with time fields.
#include <vtkCommand.h>

#include <cstdint>
#include <string>
#if defined(__SANITIZE_ADDRESS__)
#include <sanitizer/lsan_interface.h>
#endif

class vtkUnstructuredGrid;
class vtkRenderWindow;

namespace mpm::vtk_internal {

/// Collects the first error a VTK object reports instead of letting VTK print it.
class ErrorCatcher : public vtkCommand {
 public:
  static ErrorCatcher* New() { return new ErrorCatcher; }
  void Execute(vtkObject*, unsigned long event, void* data) override {
    if (event == vtkCommand::ErrorEvent && message.empty())
      message = data ? static_cast<const char*>(data) : "unknown VTK error";
  }
  std::string message;
};

/// Why a VTK writer failed: its own error message (with the temporary name `written` shown
/// as `path`), else its error code, else the pipeline's.
std::string writer_failure(const ErrorCatcher& own, unsigned long code,
                           const ErrorCatcher& pipeline, const std::string& written,
                           const std::string& path);

/// A file written under a temporary name next to its target and renamed over it once
/// complete, so that a failed write leaves neither half a file nor a damaged old one.
/// Targets that exist and are not regular files (devices, pipes, symbolic links) are
/// written in place and never removed.
class FileTarget {
 public:
  /// Throws InputError when `path` is a directory.
  explicit FileTarget(std::string path);
  ~FileTarget();
  FileTarget(const FileTarget&) = delete;
  FileTarget& operator=(const FileTarget&) = delete;
  /// The name to write to.
  const std::string& write_path() const { return write_path_; }
  /// Renames the finished file over the target; throws IoError.
  void commit();

 private:
  std::string path_, write_path_;
  bool committed_ = false;
};

/// Writes an unstructured grid as an appended, zlib-compressed .vtu with the time fields
/// "TIME", "TimeValue" (s) and "CYCLE" (step), through a FileTarget. Throws IoError.
void write_unstructured(vtkUnstructuredGrid* grid, double time, std::int64_t step,
                        const std::string& path);

/// Held over every call into the OpenGL stack (a window's first render, the PNG written from
/// it). Under ASan (make test-asan) the allocations made meanwhile are not counted as leaks:
/// Mesa's GL driver, loaded and unloaded with each window, leaves blocks behind that
/// LeakSanitizer can pin on no module (so no suppression can name them), and VTK's PNG writer
/// leaves libpng's structures behind when it cannot write. Everything else in mpm-post and in
/// the tests is checked. Nothing in other builds.
struct GraphicsStack {
#if defined(__SANITIZE_ADDRESS__)
  __lsan::ScopedDisabler leaks_not_counted;
#endif
};

/// Renders the window once and writes its back buffer as a PNG through a FileTarget. Throws
/// IoError.
void write_png(vtkRenderWindow* window, const std::string& path);

}  // namespace mpm::vtk_internal
