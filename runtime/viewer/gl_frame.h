// An offscreen frame: RGBA32F colour (scene-linear radiance, alpha = coverage) and a depth buffer.
// The viewer draws every frame into one and shows it through the display transform; scripted mode
// and the tests read it back.
#pragma once

#include <epoxy/gl.h>
#include <opencv2/core.hpp>

namespace rsibr::viewer {

class GlFrame {
 public:
  GlFrame(int width, int height);  // needs a current context; throws when incomplete
  ~GlFrame();
  GlFrame(const GlFrame&) = delete;
  GlFrame& operator=(const GlFrame&) = delete;

  int width() const { return width_; }
  int height() const { return height_; }
  GLuint texture() const { return colour_; }
  // Binds the framebuffer, sets the viewport to the whole frame, clears colour to 0 and depth to 1.
  void bind_and_clear() const;
  // CV_32FC4 RGBA, row 0 at the top (the image convention; GL's rows are flipped).
  cv::Mat read() const;

 private:
  int width_, height_;
  GLuint fbo_ = 0, colour_ = 0, depth_ = 0;
};

}  // namespace rsibr::viewer
