#pragma once
/// The X display of off-screen rendering (internal to mpm_vtk; ensure_display is public).

namespace mpm::vtk_internal {

/// A connection to the X display, opened by us and handed to VTK's render window.
/// VTK's X render window aborts the process when it cannot connect; opening the display first
/// turns that into an error. Holding the connection for the whole render also keeps an Xvfb
/// started without -noreset from resetting (and refusing connections) between clients.
/// Xlib is already loaded with VTK's OpenGL module; it is looked up at run time rather than
/// linked. When Xlib is not found, get() is null and VTK connects by itself.
class XDisplay {
 public:
  /// Opens the display `name` (the value of DISPLAY), trying for about a second.
  explicit XDisplay(const char* name);
  ~XDisplay();
  XDisplay(const XDisplay&) = delete;
  XDisplay& operator=(const XDisplay&) = delete;
  /// False when Xlib was found and the display could not be opened.
  bool ok() const { return !xlib_ || display_; }
  /// The Xlib Display*, or null.
  void* get() const { return display_; }

 private:
  bool xlib_ = false;
  void* display_ = nullptr;
  void* close_ = nullptr;
};

}  // namespace mpm::vtk_internal
