#include "hdr/alignment.h"

#include <opencv2/imgproc.hpp>
#include <opencv2/photo.hpp>

#include <algorithm>

namespace rsibr {

std::vector<cv::Point> align_brackets(BracketSet& b, int max_bits) {
  const std::size_t P = b.size();
  std::vector<cv::Point> shifts(P, cv::Point(0, 0));
  if (P < 2) return shifts;
  std::vector<cv::Mat> grey(P);
  const double scale = b.max_code == 255 ? 1.0 : 1.0 / 257.0;
  for (std::size_t j = 0; j < P; ++j) {
    cv::Mat eight;
    b.codes[j].convertTo(eight, CV_8UC3, scale);
    cv::cvtColor(eight, grey[j], cv::COLOR_RGB2GRAY);
  }
  const std::size_t mid = P / 2;
  // Each pyramid level halves the image; keep the coarsest level at least 16 pixels across.
  int bits = 0;
  while (bits < max_bits && (std::min(b.rows(), b.cols()) >> (bits + 1)) >= 16) ++bits;
  auto mtb = cv::createAlignMTB(bits, 4, true);
  for (std::size_t j = 0; j < P; ++j) {
    if (j == mid) continue;
    // calculateShift(img0, img1) is the shift that moves img1 onto img0.
    shifts[j] = mtb->calculateShift(grey[mid], grey[j]);
    if (shifts[j] == cv::Point(0, 0)) continue;
    const cv::Mat M = (cv::Mat_<double>(2, 3) << 1, 0, shifts[j].x, 0, 1, shifts[j].y);
    cv::Mat moved;
    cv::warpAffine(b.codes[j], moved, M, b.codes[j].size(), cv::INTER_NEAREST, cv::BORDER_REPLICATE);
    b.codes[j] = moved;
    if (!b.saturated.empty() && !b.saturated[j].empty()) {
      cv::warpAffine(b.saturated[j], moved, M, b.saturated[j].size(), cv::INTER_NEAREST, cv::BORDER_REPLICATE);
      b.saturated[j] = moved;
    }
  }
  return shifts;
}

}  // namespace rsibr
