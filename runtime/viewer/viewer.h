// rsibr's interactive viewer: a mesh lit by one map set, or two compared side by side or with a wipe
// (e.g. captured against computed), orbited live. Each frame the mesh pass (runtime/viewer/mesh_pass.h)
// draws with the runtime's formulas per pixel in a fragment shader, or from the CPU engine's
// destination map (paper mode), into a float frame that the display pass (OpenColorIO, exposure)
// shows. A Dear ImGui panel shows the map sets, the located triangle and its weights, the warp and
// mode, the display transform, toggles and frame times (docs/user-guide.md, "Viewer").
// Scripted mode runs a turntable without interaction (hidden window; Xvfb + Mesa llvmpipe in CI) and
// hands each frame back, read from the GPU, for screenshots and benchmarks.
#pragma once

#include "core/camera.h"
#include "formats/map_set.h"
#include "core/mesh.h"
#include "runtime/blend.h"
#include "runtime/renderer.h"

#include <opencv2/core.hpp>

#include <functional>
#include <string>
#include <vector>

namespace rsibr::viewer {

struct ViewerScene {
  const Mesh* mesh = nullptr;
  std::vector<const MapSet*> sets;  // one, or two to compare
  std::vector<std::string> names;   // shown in the panel (file names)
};

enum class Compare { Wipe, SideBySide };

struct ViewerSettings {
  RenderMode mode = RenderMode::PerPixel;  // per-pixel: the shader; paper: the CPU engine's map
  std::string warp = "precomputed";        // paper mode's destination-map warp
  int map_size = 0;                        // paper mode's destination size (0: the first set's width)
  int rings = 16;                          // tessellated warp
  BlendOptions blend;                      // rim_fade, use_confidence
  float exposure = 0;                      // stops
  std::string display, view;               // OCIO (empty: the config's defaults)
  Compare compare = Compare::Wipe;
  float wipe = 0.5f;         // fraction of the width showing the first set
  bool show_weight = false;  // the singularity fades (sum_i a_i) instead of radiance
  // The camera of the first frame (its size is the frame's), and the orbit's pivot and axis.
  Camera camera;
  Vec3 pivot = Vec3::Zero();
  Vec3 up = Vec3(0, 1, 0);
  double vfov_deg = 40;
};

struct ScriptedFrame {
  int index = 0;
  Camera camera;
  cv::Mat rgba;              // CV_32FC4 scene-linear, alpha = coverage (empty unless read back)
  double seconds = 0;        // the frame's work: mesh pass(es), the CPU blend in paper mode, the
                             // display pass to the window, up to glFinish (not the read back)
  double seconds_blend = 0;  // of which the CPU destination maps (paper mode)
};

// Frames k = 0..frames-1 of a turntable (core/camera.h orbit(settings.camera, pivot, up, k, frames),
// the frames of `rsibr render --turntable`), drawn in a hidden window of the frame's size. The sink
// gets each frame; read_back: with its pixels. gl_renderer (optional): the driver's name.
// Throws std::runtime_error without a display or OpenGL 3.3.
void run_scripted(const ViewerScene& scene, const ViewerSettings& settings, int frames, bool read_back,
                  const std::function<void(const ScriptedFrame&)>& sink, std::string* gl_renderer = nullptr);

// The interactive window (settings.camera's size), until it is closed or Esc. Returns 0.
int run_interactive(const ViewerScene& scene, const ViewerSettings& settings);

// The keyboard and mouse help shown in the window and by `rsibr view --help`.
extern const char* const kViewerKeys;

}  // namespace rsibr::viewer
