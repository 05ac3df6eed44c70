#include "core/preview_exposure.h"
#include "core/luminance.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace rsibr {
namespace {

// Appends the luminances of the pixels of `rgb` that hold light, every step-th row and column.
void collect(const cv::Mat& rgb, const cv::Mat& mask, int step, std::vector<float>& lum) {
  if (rgb.empty()) return;
  if (rgb.type() != CV_32FC3 && rgb.type() != CV_32FC4)
    throw std::invalid_argument("preview_exposure: expected a CV_32FC3 or CV_32FC4 image");
  if (!mask.empty() && (mask.type() != CV_8UC1 || mask.size() != rgb.size()))
    throw std::invalid_argument("preview_exposure: the mask must be CV_8UC1 of the image's size");
  const int ch = rgb.channels();
  for (int y = 0; y < rgb.rows; y += step) {
    const float* p = rgb.ptr<float>(y);
    const unsigned char* m = mask.empty() ? nullptr : mask.ptr<unsigned char>(y);
    for (int x = 0; x < rgb.cols; x += step) {
      if (m && !m[x]) continue;
      const float* v = p + std::size_t(x) * std::size_t(ch);
      if (ch == 4 && !(v[3] > 0)) continue;
      const float l = float(luminance(v));
      if (std::isfinite(l) && l > 0) lum.push_back(l);
    }
  }
}

}  // namespace

float preview_exposure(const std::vector<cv::Mat>& rgb, const std::vector<cv::Mat>& masks) {
  if (!masks.empty() && masks.size() != rgb.size())
    throw std::invalid_argument("preview_exposure: one mask per image, or none");
  double pixels = 0;
  for (const cv::Mat& m : rgb) pixels += double(m.total());
  const int step = std::max(1, int(std::ceil(std::sqrt(pixels / double(1 << 20)))));
  std::vector<float> lum;
  for (std::size_t i = 0; i < rgb.size(); ++i) collect(rgb[i], masks.empty() ? cv::Mat() : masks[i], step, lum);
  if (lum.empty()) return 0.f;
  const auto mid = lum.begin() + long(lum.size() / 2);
  std::nth_element(lum.begin(), mid, lum.end());
  return float(std::log2(0.18 / double(*mid)));
}

float preview_exposure(const cv::Mat& rgb, const cv::Mat& mask) {
  return preview_exposure(std::vector<cv::Mat>{rgb},
                          mask.empty() ? std::vector<cv::Mat>{} : std::vector<cv::Mat>{mask});
}

}  // namespace rsibr
