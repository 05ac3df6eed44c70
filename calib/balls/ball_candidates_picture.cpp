#include "calib/balls/ball_candidates_picture.h"
#include "formats/file_error.h"

#include "formats/atomic_file.h"
#include "core/colour.h"
#include "formats/image_codecs.h"
#include "core/preview_exposure.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rsibr {

cv::Mat ball_candidates_picture(const cv::Mat& image, const std::vector<BallCandidate>& candidates,
                                const std::vector<int>& chosen, int max_side) {
  // Shrunk in linear light, then encoded: the encoding costs the picture's pixels, not the photo's.
  const double scale = std::min(1.0, double(max_side) / double(std::max(image.cols, image.rows)));
  cv::Mat shown;
  if (scale < 1)
    cv::resize(image, shown, cv::Size(), scale, scale, cv::INTER_AREA);
  else
    shown = image;
  shown = display_encode(shown, preview_exposure(image));
  // Lines and numbers sized to the picture, not the photo: readable on a 12 MP frame and a crop.
  const int thick = std::max(1, int(std::lround(std::max(shown.cols, shown.rows) / 500.0)));
  const double font = std::max(0.5, std::max(shown.cols, shown.rows) / 900.0);
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const BallLocation& l = candidates[i].loc;
    const bool picked = std::find(chosen.begin(), chosen.end(), int(i)) != chosen.end();
    const cv::Scalar colour = picked ? cv::Scalar(60, 220, 60) : cv::Scalar(0, 150, 255);  // BGR
    const cv::Point c(int(std::lround(l.centre_px.x() * scale)), int(std::lround(l.centre_px.y() * scale)));
    cv::circle(shown, c, int(std::lround(l.radius_px * scale)), colour, thick, cv::LINE_AA);
    cv::drawMarker(shown, c, colour, cv::MARKER_CROSS, 4 * thick + 6, thick);
    const std::string label = std::to_string(i);
    int base = 0;
    const cv::Size ts = cv::getTextSize(label, cv::FONT_HERSHEY_SIMPLEX, font, thick + 1, &base);
    const cv::Point at(std::clamp(c.x - ts.width / 2, 0, std::max(0, shown.cols - ts.width)),
                       std::clamp(c.y - int(l.radius_px * scale) - 4 * thick, ts.height, shown.rows - base));
    cv::putText(shown, label, at, cv::FONT_HERSHEY_SIMPLEX, font, cv::Scalar(0, 0, 0), thick + 3, cv::LINE_AA);
    cv::putText(shown, label, at, cv::FONT_HERSHEY_SIMPLEX, font, colour, thick + 1, cv::LINE_AA);
  }
  return shown;
}

void write_ball_candidates_picture(const std::filesystem::path& png, const cv::Mat& image, const ViewCandidates& vc) {
  std::vector<int> chosen;
  for (const int p : vc.pick)
    if (p >= 0) chosen.push_back(p);
  const cv::Mat shown = ball_candidates_picture(image, vc.cands, chosen);
  write_atomically(png, [&](const std::string& tmp) {
    if (!write_image(tmp, shown)) throw FileError(png.string(), "cannot write the PNG image", {}, FileRole::Output);
  });
}

}  // namespace rsibr
