// The one hidden GLFW window (OpenGL 3.3 core context) of the viewer test executable, created on
// first use. Run under `xvfb-run -a` without a display (tests/CMakeLists.txt does).
#pragma once

#include "runtime/viewer/gl_window.h"

namespace rsibr::testing {

inline viewer::GlWindow& gl_test_context() {
  static viewer::GlWindow w(64, 64, "rsibr viewer tests", false);
  w.make_current();  // another window (run_scripted's) may have been current
  return w;
}

}  // namespace rsibr::testing
