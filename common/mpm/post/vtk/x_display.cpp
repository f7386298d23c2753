// The X display of off-screen rendering: opened for VTK, or provided by xvfb-run.
#include "mpm/post/vtk/x_display.hpp"

#include <dlfcn.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "mpm/core/error.hpp"
#include "mpm/post/vtk/vtk_output.hpp"

namespace mpm {

namespace vtk_internal {

XDisplay::XDisplay(const char* name) {
  void* open = ::dlsym(RTLD_DEFAULT, "XOpenDisplay");
  close_ = ::dlsym(RTLD_DEFAULT, "XCloseDisplay");
  if (!open || !close_) {
    void* lib = ::dlopen("libX11.so.6", RTLD_LAZY | RTLD_LOCAL);
    if (!lib) return;
    open = ::dlsym(lib, "XOpenDisplay");
    close_ = ::dlsym(lib, "XCloseDisplay");
    if (!open || !close_) return;
  }
  xlib_ = true;
  // A server that is resetting refuses connections for a moment: try for about a second.
  for (int attempt = 0; attempt < 10 && !display_; ++attempt) {
    if (attempt > 0) ::usleep(100000);
    display_ = reinterpret_cast<void* (*)(const char*)>(open)(name);
  }
}

XDisplay::~XDisplay() {
  if (display_) reinterpret_cast<int (*)(void*)>(close_)(display_);
}

}  // namespace vtk_internal

void ensure_display(int argc, char** argv) {
  const char* display = std::getenv("DISPLAY");
  if (display && *display) return;
  const char* under = std::getenv("MPM_UNDER_XVFB");
  if (under && *under)
    throw InputError("render",
                     "no display even under xvfb-run (MPM_UNDER_XVFB is set but DISPLAY is not); "
                     "check that Xvfb starts (xvfb-run -a xdpyinfo) or set DISPLAY");
  ::setenv("MPM_UNDER_XVFB", "1", 1);

  // Re-run this very program: /proc/self/exe survives a relative argv[0] or a changed PATH.
  std::string self;
  char buf[4096];
  const ssize_t len = ::readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (len > 0)
    self.assign(buf, std::size_t(len));
  else if (argc > 0 && argv && argv[0])
    self = argv[0];
  std::vector<std::string> args = {"xvfb-run", "-a", "-s", "-screen 0 1920x1080x24 -noreset", self};
  for (int i = 1; i < argc; ++i) args.emplace_back(argv[i]);
  std::vector<char*> cargs;
  for (auto& a : args) cargs.push_back(a.data());
  cargs.push_back(nullptr);
  std::fflush(nullptr);  // stdio buffers do not survive exec
  ::execvp("xvfb-run", cargs.data());
  ::unsetenv("MPM_UNDER_XVFB");
  throw InputError("render", "no display and no xvfb-run; install xvfb or set DISPLAY");
}

}  // namespace mpm
