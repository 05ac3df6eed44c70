#include "calib/orientation/pair_matches_picture.h"
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

cv::Mat pair_matches_picture(const cv::Mat& a, const cv::Mat& b, const PairOrientation& pair, int height) {
  if (a.empty() || b.empty() || height < 16) throw std::invalid_argument("pair matches picture: empty views");
  // Shrunk in linear light (area averages of radiance), then encoded for display: the encoding
  // costs the picture's pixels, not the photo's. The exposure is the whole photo's.
  const double ka = double(height) / a.rows, kb = double(height) / b.rows;
  cv::Mat sa, sb;
  cv::resize(a, sa, cv::Size(std::max(1, int(std::lround(a.cols * ka))), height), 0, 0, cv::INTER_AREA);
  cv::resize(b, sb, cv::Size(std::max(1, int(std::lround(b.cols * kb))), height), 0, 0, cv::INTER_AREA);
  sa = display_encode(sa, preview_exposure(a));
  sb = display_encode(sb, preview_exposure(b));
  cv::Mat shown;
  cv::hconcat(sa, sb, shown);
  const int thick = std::max(1, height / 400);
  // Outliers first, so the inliers are drawn over them.
  for (const bool inliers : {false, true})
    for (std::size_t i = 0; i < pair.matches_px.size(); ++i) {
      if (bool(pair.match_inlier[i]) != inliers) continue;
      const cv::Scalar colour = inliers ? cv::Scalar(60, 220, 60) : cv::Scalar(40, 40, 230);  // BGR
      const Vec2& pa = pair.matches_px[i].first;
      const Vec2& pb = pair.matches_px[i].second;
      const cv::Point qa(int(std::lround(pa.x() * ka)), int(std::lround(pa.y() * ka)));
      const cv::Point qb(int(std::lround(pb.x() * kb)) + sa.cols, int(std::lround(pb.y() * kb)));
      cv::line(shown, qa, qb, colour, thick, cv::LINE_AA);
      cv::circle(shown, qa, 2 * thick + 1, colour, thick, cv::LINE_AA);
      cv::circle(shown, qb, 2 * thick + 1, colour, thick, cv::LINE_AA);
    }
  return shown;
}

void write_pair_matches_picture(const std::filesystem::path& png, const cv::Mat& a, const cv::Mat& b,
                                const PairOrientation& pair) {
  const cv::Mat shown = pair_matches_picture(a, b, pair);
  write_atomically(png, [&](const std::string& tmp) {
    if (!write_image(tmp, shown)) throw FileError(png.string(), "cannot write the PNG image", {}, FileRole::Output);
  });
}

}  // namespace rsibr
