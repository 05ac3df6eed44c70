#include "hdr/merged_colour.h"

#include "core/colour.h"

#include <OpenColorIO/OpenColorIO.h>

#include <cmath>
#include <stdexcept>

namespace rsibr {

cv::Matx33f colour_conversion_matrix(const std::string& from, const std::string& to) {
  cv::Mat basis(1, 6, CV_32FC3);
  for (int i = 0; i < 3; ++i) {
    cv::Vec3f e(0, 0, 0);
    e[i] = 1;
    basis.at<cv::Vec3f>(0, i) = e;
    basis.at<cv::Vec3f>(0, 3 + i) = 2 * e;
  }
  convert_colour_space(basis, from, to);
  cv::Matx33f m;
  for (int col = 0; col < 3; ++col) {
    const cv::Vec3f once = basis.at<cv::Vec3f>(0, col), twice = basis.at<cv::Vec3f>(0, 3 + col);
    for (int row = 0; row < 3; ++row) {
      if (std::abs(twice[row] - 2 * once[row]) > 1e-4f * (1 + std::abs(twice[row])))
        throw std::runtime_error("colour space '" + from + "' -> '" + to +
                                 "': not a linear conversion (merged radiance needs a linear camera space)");
      m(row, col) = once[row];
    }
  }
  return m;
}

std::string merged_colour_space(const std::string& given, bool raw) {
  if (!given.empty()) return given;
  if (raw && colour_config()->getColorSpace("lin_rec709")) return "lin_rec709";
  return "";
}

void merged_to_working_space(MergedImage& m, const std::string& from) {
  const std::string working = working_space();
  if (from.empty() || from == working) return;
  const cv::Matx33f M = colour_conversion_matrix(from, working);
  cv::transform(m.radiance, m.radiance, M);
  cv::Matx33f sq;
  for (int i = 0; i < 9; ++i) sq.val[i] = M.val[i] * M.val[i];
  if (!m.variance.empty()) cv::transform(m.variance, m.variance, sq);
}

void apply_white_balance(MergedImage& m, const cv::Vec3f& g) {
  m.radiance.forEach<cv::Vec3f>([&](cv::Vec3f& p, const int*) { p = p.mul(g); });
  if (!m.variance.empty()) m.variance.forEach<cv::Vec3f>([&](cv::Vec3f& p, const int*) { p = p.mul(g.mul(g)); });
}

}  // namespace rsibr
