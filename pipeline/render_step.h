// The `render` step of rsibr process (pipeline/process_pipeline.h), the last before the report: the
// probe baked into a map set of icosa views of a BRDF (bake/map_set_bake.h), then a turntable of a
// mesh (or a built-in torus) rendered with it through the runtime (runtime/renderer.h) ->
// OUT/maps.exr and OUT/frame_NN.png, exposed at the probe's median, and OUT/viewer.html, the same
// turntable to orbit in a browser (runtime/web_viewer_page.h).
#pragma once

#include "pipeline/step_outputs.h"

#include <cstdint>
#include <filesystem>
#include <string>

namespace rsibr {

struct RenderStep {
  std::filesystem::path probe;  // probe.exr
  std::string mesh;             // .glb/.gltf/.obj; empty: a built-in torus
  std::string brdf;             // the material's BRDF spec (YAML text)
  int views_res = 64;           // texels a side of the maps
  int frames = 8;
  int width = 320, height = 240;
  std::uint64_t seed = 0;
  bool progress = false;      // a progress bar on stderr
  std::filesystem::path out;  // the render folder
};

// The summary: mesh, triangles, material, frames, seconds per frame, display exposure, the viewer
// page and its size.
StepOutputs run_render_step(const RenderStep& s);

}  // namespace rsibr
