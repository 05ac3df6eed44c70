#include "pipeline/mask_picture.h"

#include "core/colour.h"
#include "core/sphere_map.h"

#include <opencv2/imgproc.hpp>

namespace rsibr {

cv::Mat mask_picture(const MapView& chrome, float exposure_stops, int zoom) {
  const cv::Mat shown = display_encode(chrome.rgb, exposure_stops);
  cv::Mat masked = shown.clone();
  for (int y = 0; y < masked.rows; ++y)
    for (int x = 0; x < masked.cols; ++x) {
      if (sphere_map::disc_from_pixel(Vec2(x, y), masked.cols, masked.rows).squaredNorm() >= 1.0) continue;
      const float c = chrome.confidence.empty() ? 1.f : chrome.confidence.at<float>(y, x);
      cv::Vec3b& p = masked.at<cv::Vec3b>(y, x);
      if (!(c > 0))
        p = cv::Vec3b(40, 40, 220);  // BGR red
      else
        for (int k = 0; k < 3; ++k) p[k] = cv::saturate_cast<uchar>(p[k] * (0.35 + 0.65 * c));
    }
  cv::Mat both;
  cv::hconcat(std::vector<cv::Mat>{shown, cv::Mat(shown.rows, 2, CV_8UC3, cv::Scalar(255, 255, 255)), masked}, both);
  cv::Mat big;
  cv::resize(both, big, cv::Size(), zoom, zoom, cv::INTER_NEAREST);
  return big;
}

}  // namespace rsibr
