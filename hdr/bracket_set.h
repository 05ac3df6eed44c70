// The bracketed photos of one view, loaded as integer codes: every image the same size, RGB
// channel order, CV_16UC3 (8-bit files are widened without scaling, so codes stay 0..255 and
// max_code says which range applies). Exposures sorted ascending.
#pragma once

#include "core/photo_set.h"
#include "hdr/exposure_metadata.h"

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace rsibr {

struct BracketSet {
  std::vector<cv::Mat> codes;               // CV_16UC3, RGB
  std::vector<double> exposures;            // relative exposures e_j (ascending)
  std::vector<ResolvedExposure> metadata;   // per bracket, same order
  std::vector<std::string> files;           // per bracket, same order
  int max_code = 255;                       // 255 (8-bit files) or 65535 (16-bit)
  bool lossy = false;                       // some bracket is a lossy file (JPEG: .jpg, .jpeg)

  int rows() const { return codes.empty() ? 0 : codes[0].rows; }
  int cols() const { return codes.empty() ? 0 : codes[0].cols; }
  std::size_t size() const { return codes.size(); }
};

// Reads a view's brackets with OpenCV (PNG/JPEG 8-bit, TIFF/PNG 16-bit; grey images become three
// equal channels) and their exposures (resolve_exposure). Throws std::runtime_error naming the
// file for unreadable images, other depths, mixed sizes or depths, or two brackets with the same
// exposure.
BracketSet load_brackets(const PhotoView& view);

// Builds a set from in-memory images (CV_8UC3 or CV_16UC3, RGB) and exposures; sorts by exposure.
// Same checks as load_brackets. For tests and benchmarks (lossy: the images went through JPEG).
BracketSet make_brackets(std::vector<cv::Mat> images, std::vector<double> exposures,
                         std::vector<std::string> names = {}, bool lossy = false);

}  // namespace rsibr
