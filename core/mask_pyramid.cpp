#include "core/mask_pyramid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rsibr {

MaskPyramid::MaskPyramid(int width, int height, const std::function<float(int, int, int)>& author) {
  if (width < 1 || height < 1) throw std::invalid_argument("mask pyramid: the size must be at least 1 x 1");
  for (int l = 0;; ++l) {
    const int w = std::max(1, width >> l), h = std::max(1, height >> l);
    cv::Mat m(h, w, CV_32FC1);
    for (int r = 0; r < h; ++r)
      for (int c = 0; c < w; ++c) {
        const float v = author(l, c, r);
        m.at<float>(r, c) = v > 0.0f ? std::min(v, 1.0f) : 0.0f;  // NaN fails v > 0: 0
      }
    levels_.push_back(m);
    if (w == 1 && h == 1) break;
  }
}

cv::Rect MaskPyramid::footprint(int W, int H, int level, int col, int row) {
  const int lw = std::max(1, W >> level), lh = std::max(1, H >> level), s = 1 << level;
  const int c0 = std::min(col * s, W - 1), r0 = std::min(row * s, H - 1);
  const int c1 = col == lw - 1 ? W : std::min((col + 1) * s, W);
  const int r1 = row == lh - 1 ? H : std::min((row + 1) * s, H);
  return cv::Rect(c0, r0, std::max(1, c1 - c0), std::max(1, r1 - r0));
}

float MaskPyramid::sample_level(const Vec2& p0, int level) const {
  const cv::Mat& m = levels_.at(std::size_t(std::clamp(level, 0, levels() - 1)));
  // Level-0 pixel -> level-l pixel: scale by the level's size relative to level 0.
  const double sx = double(m.cols) / width(), sy = double(m.rows) / height();
  double x = (p0.x() + 0.5) * sx - 0.5, y = (p0.y() + 0.5) * sy - 0.5;
  if (!std::isfinite(x) || !std::isfinite(y)) return 0.0f;
  x = std::clamp(x, 0.0, double(m.cols - 1));
  y = std::clamp(y, 0.0, double(m.rows - 1));
  const int c0 = std::min(int(x), m.cols - 1), r0 = std::min(int(y), m.rows - 1);
  const int c1 = std::min(c0 + 1, m.cols - 1), r1 = std::min(r0 + 1, m.rows - 1);
  const double fx = x - c0, fy = y - r0;
  const double top = (1 - fx) * m.at<float>(r0, c0) + fx * m.at<float>(r0, c1);
  const double bottom = (1 - fx) * m.at<float>(r1, c0) + fx * m.at<float>(r1, c1);
  return float((1 - fy) * top + fy * bottom);
}

float MaskPyramid::sample(const Vec2& p0, double lod) const {
  if (!(lod > 0)) return sample_level(p0, 0);  // also NaN
  const double l = std::min(lod, double(levels() - 1));
  const int l0 = int(l);
  const double f = l - l0;
  const float a = sample_level(p0, l0);
  return f > 0 ? float((1 - f) * a + f * sample_level(p0, l0 + 1)) : a;
}

}  // namespace rsibr
