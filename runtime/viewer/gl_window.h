// A GLFW window with an OpenGL 3.3 core context (function pointers through libepoxy), for the viewer
// and for its scripted and test modes (a hidden window: the frame is drawn into an offscreen
// framebuffer, so its size need not match the window's). Several may exist (GLFW is initialised
// with the first and terminated with the last); the newest is current. Main thread only.
#pragma once

#include <string>

struct GLFWwindow;

namespace rsibr::viewer {

class GlWindow {
 public:
  // Throws std::runtime_error with GLFW's description when there is no display (e.g. $DISPLAY unset;
  // run under `xvfb-run -a`) or the driver has no OpenGL 3.3 core profile.
  GlWindow(int width, int height, const std::string& title, bool visible);
  ~GlWindow();
  GlWindow(const GlWindow&) = delete;
  GlWindow& operator=(const GlWindow&) = delete;

  GLFWwindow* handle() const { return window_; }
  void make_current() const;
  // GL_RENDERER and GL_VERSION, e.g. "llvmpipe (LLVM 15.0.6, 256 bits), 4.5 (Core Profile) Mesa 22.3.6".
  std::string renderer() const;

 private:
  GLFWwindow* window_ = nullptr;
};

}  // namespace rsibr::viewer
