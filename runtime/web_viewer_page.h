// The viewer in a web page: one self-contained HTML file (no network) that draws a mesh lit by a map
// set with WebGL2, per pixel, with the desktop viewer's shaders (runtime/map_shader.h, compiled as
// GLSL ES 3.00) over the same texture layout (runtime/gpu_map_data.h): one rule, not a copy.
//
// Embedded: the maps as half floats (RGBA16F; a set brighter than half's range is divided by a power
// of two and the display multiplies it back), the view-set tables as float32 and int32, the mesh
// (float32 positions and normals, uint32 indices) and the display transform as a 33^3 lookup table
// of display_encode's transform (core/colour.h apply_display_transform; $OCIO honoured) over log2
// radiance in [-14, 6] after exposure, read trilinearly.
// The radiance is drawn into an RGBA32F frame (EXT_color_buffer_float), then shown through
// 2^exposure and the table. A second set (captured against computed) is drawn with the same camera
// right of a wipe the user drags. Without WebGL2 the page says so and shows `fallback_html`.
//
// Mouse: drag orbits about the pivot around world up, the wheel moves the camera closer or further;
// the exposure slider is in stops. For tests and scripts, `window.rsibrViewer`:
//   setCamera({width, height, fx, fy, cx, cy, eye: [x,y,z], world_from_cam: [9, row-major]})
//     the mrcal pinhole of core/camera.h (the canvas takes its size);
//   radiance() -> Float32Array, width x height x 4, top row first: the drawn RGBA radiance
//     (alpha 1 where the mesh covers the pixel, 0 elsewhere);
//   displayed() -> Uint8Array, the same layout: the canvas as shown (8-bit RGBA);
//   setExposure(stops); setWipe(fraction of the width showing the first set); camera() -> the camera;
//   ready: true once the first frame is drawn; error: the reason when WebGL2 is missing.
#pragma once

#include "core/camera.h"
#include "core/mesh.h"
#include "formats/map_set.h"
#include "runtime/blend.h"

#include <string>

namespace rsibr {

struct WebViewerPage {
  const MapSet* maps = nullptr;       // required
  const MapSet* maps2 = nullptr;      // optional: a second set, compared by a wipe (one camera)
  std::string names[2];               // the sets' names, for the wipe's labels
  const Mesh* mesh = nullptr;         // required
  BlendOptions blend;                 // rim_fade, use_confidence (gnomonic weights)
  Camera camera;                      // the first view (canvas size too)
  Vec3 pivot = Vec3::Zero();          // orbit centre, world
  Vec3 up = Vec3(0, 1, 0);            // orbit axis, world
  float exposure = 0;                 // stops
  std::string display, display_view;  // OpenColorIO display and view (empty: the config's defaults)
  std::string title;
  std::string fallback_html;  // shown without WebGL2 (e.g. the stills), may be empty
};

// The page's HTML. Throws std::invalid_argument for what the shader cannot draw (gpu_map_data's
// errors) and std::runtime_error for an unknown display transform.
std::string web_viewer_page(const WebViewerPage& page);

}  // namespace rsibr
