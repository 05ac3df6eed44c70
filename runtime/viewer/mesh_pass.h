// The viewer's mesh pass: draws a mesh lit by a map set for one camera, per pixel in the fragment
// shader or from the CPU engine's destination map (paper mode), into the bound framebuffer
// (runtime/map_shader.h states the formulas and how they match runtime/renderer.h).
#pragma once

#include "core/camera.h"
#include "runtime/renderer.h"
#include "runtime/viewer/gl_map_set.h"
#include "runtime/viewer/gl_mesh.h"
#include "runtime/viewer/gl_program.h"

#include <Eigen/Geometry>

namespace rsibr::viewer {

struct MeshPassOptions {
  RenderMode mode = RenderMode::PerPixel;
  bool show_weight = false;  // grey = sum_i a_i (the singularity fades), instead of radiance
};

class MeshPass {
 public:
  MeshPass();  // compiles the shaders; needs a current context
  // Draws into the bound framebuffer's viewport rectangle (x0, y0) (window coordinates, bottom-left)
  // of camera.width x camera.height. Paper mode first blends the destination map on the CPU
  // (set.update_destination for the camera's view direction and up). bounds: the mesh's, for the
  // depth range.
  void draw(const Camera& camera, const Eigen::AlignedBox3f& bounds, const GlMesh& mesh, GlMapSet& set,
            const MeshPassOptions& options, int x0 = 0, int y0 = 0) const;

 private:
  GlProgram per_pixel_, paper_;
};

}  // namespace rsibr::viewer
