#include "runtime/viewer/gl_window.h"

#include <epoxy/gl.h>
// After epoxy: GLFW must not include the system GL header.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <dlfcn.h>
#include <link.h>

#include <cstring>
#include <stdexcept>

namespace rsibr::viewer {
namespace {
// Windows alive (GLFW is initialised with the first and terminated with the last).
int g_windows = 0;

// Keeps the OpenGL driver modules (Mesa's .../dri/*_dri.so, libGLX_mesa) loaded until the process
// exits. Mesa unloads them when the display closes, and leak reports of the allocations they make
// and never free would then show "<unknown module>" frames that no suppression can name. Pinned,
// LeakSanitizer names them and runtime/viewer/lsan.supp suppresses exactly those modules.
void pin_gl_driver_modules() {
  dl_iterate_phdr(
      [](dl_phdr_info* info, size_t, void*) {
        const char* name = info->dlpi_name;
        if (name && (std::strstr(name, "_dri.so") || std::strstr(name, "libGLX_mesa")))
          dlopen(name, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);  // a reference never dropped
        return 0;
      },
      nullptr);
}

std::string last_glfw_error() {
  const char* description = nullptr;
  const int code = glfwGetError(&description);
  return code == GLFW_NO_ERROR ? std::string("unknown error") : std::string(description ? description : "?");
}
}  // namespace

GlWindow::GlWindow(int width, int height, const std::string& title, bool visible) {
  if (g_windows == 0 && !glfwInit())
    throw std::runtime_error("cannot open a window (" + last_glfw_error() +
                             "); the viewer needs a display (run under `xvfb-run -a` without one)");
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_VISIBLE, visible ? GLFW_TRUE : GLFW_FALSE);
  window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!window_) {
    const std::string why = last_glfw_error();
    if (g_windows == 0) glfwTerminate();
    throw std::runtime_error("cannot create an OpenGL 3.3 core window (" + why + ")");
  }
  ++g_windows;
  glfwMakeContextCurrent(window_);
  pin_gl_driver_modules();
}

GlWindow::~GlWindow() {
  glfwDestroyWindow(window_);
  if (--g_windows == 0) glfwTerminate();
}

void GlWindow::make_current() const { glfwMakeContextCurrent(window_); }

std::string GlWindow::renderer() const {
  const auto* r = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const auto* v = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  return std::string(r ? r : "?") + ", " + (v ? v : "?");
}

}  // namespace rsibr::viewer
