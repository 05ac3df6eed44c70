// The viewer's display pass (OpenColorIO's GPU shader and its LUTs) against the CPU display encoding
// that rsibr render's PNGs use (core/colour.h display_encode). Runs under Xvfb (tests/CMakeLists.txt).
#include "runtime/viewer/display_transform.h"
#include "runtime/viewer/gl_frame.h"

#include "core/colour.h"

#include "viewer/gl_test_context.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rsibr {
namespace {

using viewer::DisplayTransform;
using viewer::GlFrame;

// Linear values from 0 to 4 (past the display's 1) in every channel mix, alpha 1; the last texel
// has alpha 0 (nothing drawn: the background).
cv::Mat ramp(int n) {
  cv::Mat m(1, n, CV_32FC4);
  for (int i = 0; i < n; ++i) {
    const float t = 4.f * float(i) / float(n - 2);
    m.at<cv::Vec4f>(0, i) = cv::Vec4f(t, 0.5f * t, 0.25f * t * t, 1.f);
  }
  m.at<cv::Vec4f>(0, n - 1) = cv::Vec4f(1, 1, 1, 0);
  return m;
}

// Every view of the default display, at two exposures: the GPU result is the CPU encoding to within
// its 8-bit quantisation (the CPU rounds to the nearest level: |gpu * 255 - cpu| <= 0.5, plus float
// slack for the shader's own pow/exp2).
TEST(DisplayTransform, MatchesTheCpuDisplayEncoding) {
  testing::gl_test_context();
  const int n = 258;
  const cv::Mat linear = ramp(n);
  for (const std::string& view : DisplayTransform::views()) {
    const DisplayTransform display("", view);
    for (float exposure : {0.f, -1.5f}) {
      const GlFrame source(n, 1), target(n, 1);
      glBindTexture(GL_TEXTURE_2D, source.texture());
      glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, n, 1, GL_RGBA, GL_FLOAT, linear.data);
      target.bind_and_clear();
      display.draw(source.texture(), exposure, 0, 0, n, 1);
      const cv::Mat gpu = target.read();
      const cv::Mat bgr = display_encode(linear, exposure, "", view);
      double worst = 0;
      for (int i = 0; i < n - 1; ++i)
        for (int k = 0; k < 3; ++k)
          worst = std::max(worst, std::abs(255.0 * gpu.at<cv::Vec4f>(0, i)[k] - bgr.at<cv::Vec3b>(0, i)[2 - k]));
      EXPECT_LE(worst, 0.51) << view << " at exposure " << exposure;
      const cv::Vec4f background = gpu.at<cv::Vec4f>(0, n - 1);
      EXPECT_FLOAT_EQ(background[0], 0.2f) << "alpha 0 shows the neutral background";
    }
  }
}

TEST(DisplayTransform, UnknownViewIsAnError) {
  testing::gl_test_context();
  EXPECT_THROW(DisplayTransform("", "no such view"), std::runtime_error);
  EXPECT_THROW(DisplayTransform("no such display", ""), std::runtime_error);
}

}  // namespace
}  // namespace rsibr
