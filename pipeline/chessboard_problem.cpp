#include "pipeline/chessboard_problem.h"

#include "hdr/raw_image.h"
#include "formats/image_codecs.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include <stdexcept>

namespace rsibr {

namespace {

// A RAW board (linear codes) as the 8-bit grey picture the corner finder expects: its 99th
// percentile at 255, a 1/2.2 power in between (corners need contrast in the dark squares too).
cv::Mat raw_board_grey8(const std::filesystem::path& file) {
  const cv::Mat codes = read_raw_image(file).codes;
  cv::Mat grey;
  cv::cvtColor(codes, grey, cv::COLOR_RGB2GRAY);
  std::vector<std::uint16_t> v(grey.begin<std::uint16_t>(), grey.end<std::uint16_t>());
  const auto k = v.begin() + long(v.size() * 99 / 100);
  std::nth_element(v.begin(), k, v.end());
  const double top = std::max(1.0, double(*k));
  cv::Mat out(grey.size(), CV_8UC1);
  for (int y = 0; y < grey.rows; ++y)
    for (int x = 0; x < grey.cols; ++x)
      out.at<unsigned char>(y, x) = cv::saturate_cast<unsigned char>(
          255.0 * std::pow(std::min(1.0, grey.at<std::uint16_t>(y, x) / top), 1 / 2.2));
  return out;
}

cv::Mat read_grey8(const std::filesystem::path& file) {
  if (is_raw_file(file)) return raw_board_grey8(file);
  cv::Mat img = read_image(file.string(), cv::IMREAD_GRAYSCALE | cv::IMREAD_ANYDEPTH);
  if (img.empty()) throw std::runtime_error(file.string() + ": cannot read the image");
  if (img.depth() == CV_16U) img.convertTo(img, CV_8U, 1.0 / 257);
  if (img.depth() != CV_8U) throw std::runtime_error(file.string() + ": expected an 8- or 16-bit image");
  return img;
}

}  // namespace

IntrinsicsProblem chessboard_problem(const PhotoSet& set, const std::string& name, std::vector<std::string>* missed,
                                     const std::function<void(double)>& progress) {
  if (!set.chessboards) throw std::invalid_argument(name + ": no chessboards listed (photoset.yaml: chessboards)");
  const ChessboardSet& cb = *set.chessboards;
  if (cb.corners_x != cb.corners_y)
    throw std::invalid_argument(name + ": chessboards.corners: mrgingham finds square grids only (got " +
                                std::to_string(cb.corners_x) + " x " + std::to_string(cb.corners_y) + ")");
  IntrinsicsProblem p;
  p.corners_x = cb.corners_x;
  p.corners_y = cb.corners_y;
  p.spacing_m = cb.spacing_m;
  for (std::size_t i = 0; i < cb.files.size(); ++i) {
    const cv::Mat img = read_grey8(cb.files[i]);
    if (p.width == 0) p.width = img.cols, p.height = img.rows;
    if (img.cols != p.width || img.rows != p.height)
      throw std::invalid_argument(cb.files[i].string() + ": " + std::to_string(img.cols) + "x" +
                                  std::to_string(img.rows) + ", the other chessboards are " + std::to_string(p.width) +
                                  "x" + std::to_string(p.height));
    const auto corners = find_chessboard(img, cb.corners_x);
    if (corners) {
      p.boards.push_back({cb.files[i].filename().string(), *corners});
    } else if (missed) {
      missed->push_back(cb.files[i].filename().string());
    }
    if (progress) progress(double(i + 1) / double(cb.files.size()));
  }
  if (p.boards.size() < 4)
    throw std::invalid_argument(name + ": chessboards found in " + std::to_string(p.boards.size()) + " of " +
                                std::to_string(cb.files.size()) +
                                " images; need at least 4 (2 per cross-validation half)");
  return p;
}

}  // namespace rsibr
