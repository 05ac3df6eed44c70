#include "cli/rgba_png.h"
#include "formats/file_error.h"

#include "formats/atomic_file.h"
#include "core/colour.h"

#include "formats/image_codecs.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rsibr::cli {

void write_rgba_png(const std::string& path, const cv::Mat& rgba, float exposure, const std::string& display,
                    const std::string& view) {
  cv::Mat straight = rgba.clone();
  for (int r = 0; r < straight.rows; ++r) {
    float* p = straight.ptr<float>(r);
    for (int c = 0; c < straight.cols; ++c, p += 4)
      if (p[3] > 0 && p[3] < 1)
        for (int k = 0; k < 3; ++k) p[k] /= p[3];
  }
  const cv::Mat bgr = display_encode(straight, exposure, display, view);
  cv::Mat bgra(bgr.rows, bgr.cols, CV_8UC4);
  for (int r = 0; r < bgr.rows; ++r) {
    const unsigned char* s = bgr.ptr<unsigned char>(r);
    const float* a = rgba.ptr<float>(r);
    unsigned char* d = bgra.ptr<unsigned char>(r);
    for (int c = 0; c < bgr.cols; ++c) {
      d[4 * c] = s[3 * c];
      d[4 * c + 1] = s[3 * c + 1];
      d[4 * c + 2] = s[3 * c + 2];
      d[4 * c + 3] = (unsigned char)std::lround(std::clamp(a[4 * c + 3], 0.f, 1.f) * 255.f);
    }
  }
  write_atomically(path, [&](const std::string& tmp) {
    if (!write_image(tmp, bgra, {cv::IMWRITE_PNG_COMPRESSION, 3}))
      throw FileError(path, "cannot write the PNG image", {}, FileRole::Output);
  });
}

}  // namespace rsibr::cli
