// The viewer's display pass: scene-linear radiance (a GlFrame's RGBA32F texture) scaled by
// 2^exposure and encoded by the OpenColorIO display/view transform on the GPU, the same transform
// rsibr render's PNG applies on the CPU (core/colour.h display_encode; $OCIO honoured). OCIO writes
// the shader function (GLSL 1.30) and its lookup tables (1D/2D and 3D textures), uploaded here.
// Pixels with alpha 0 (nothing drawn) show a neutral grey background.
#pragma once

#include "runtime/viewer/gl_program.h"

#include <epoxy/gl.h>

#include <string>
#include <vector>

namespace rsibr::viewer {

class DisplayTransform {
 public:
  // Empty names: the config's default display and its default view. Throws std::runtime_error for
  // an unknown display or view, a transform with dynamic uniforms, or a shader that does not build.
  DisplayTransform(const std::string& display = "", const std::string& view = "");
  ~DisplayTransform();
  DisplayTransform(const DisplayTransform&) = delete;
  DisplayTransform& operator=(const DisplayTransform&) = delete;

  const std::string& display() const { return display_; }
  const std::string& view() const { return view_; }
  // The config's views of the display (for the panel's list).
  static std::vector<std::string> views(const std::string& display = "");

  // Draws frame_texture (W x H, drawn at window origin (x0, y0)) into the bound framebuffer's viewport.
  void draw(GLuint frame_texture, float exposure_stops, int x0, int y0, int width, int height) const;

 private:
  std::string display_, view_;
  GlProgram program_;
  GLuint vao_ = 0;
  struct Lut {
    GLenum target;
    GLuint texture;
    std::string sampler;
  };
  std::vector<Lut> luts_;
};

}  // namespace rsibr::viewer
