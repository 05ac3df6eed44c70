// The bracketed photos of one view, loaded as integer codes: every image the same size, RGB
// channel order, CV_16UC3 (8-bit files are widened without scaling, so codes stay 0..255 and
// max_code says which range applies). Exposures sorted ascending. Camera RAW files (hdr/raw_image.h)
// load as linear 16-bit codes, 65535 marking saturation; a view's brackets are all RAW or none.
#pragma once

#include "formats/photo_set.h"
#include "hdr/exposure_metadata.h"
#include "hdr/raw_image.h"

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace rsibr {

struct BracketSet {
  std::vector<cv::Mat> codes;              // CV_16UC3, RGB
  std::vector<double> exposures;           // relative exposures e_j (ascending)
  std::vector<ResolvedExposure> metadata;  // per bracket, same order
  std::vector<std::string> files;          // per bracket, same order
  int max_code = 255;                      // 255 (8-bit files) or 65535 (16-bit)
  bool lossy = false;                      // some bracket is a lossy file (JPEG: .jpg, .jpeg)
  bool raw = false;                        // every bracket a camera RAW file: linear codes
  std::vector<RawInfo> raw_info;           // per bracket when raw, same order
  // Per bracket (same order), or empty: CV_8UC1, non-zero where the file itself says the pixel is
  // saturated (RAW: hdr/raw_image.h), whatever its codes; the merge leaves those pixels out of
  // the bracket (and so, by the consistency rule, out of every longer one).
  std::vector<cv::Mat> saturated;
  // Per bracket (same order), or empty: CV_8UC1, zero where the bracket holds no data (padding
  // of a smaller file, the edge a shift uncovered: hdr/alignment.h); the merge leaves those
  // pixels out of that bracket only.
  std::vector<cv::Mat> covered;
  bool fitted_sizes = false;         // files of different sizes, centred on the middle bracket's frame
  std::vector<cv::Size> file_sizes;  // per bracket, as read

  int rows() const { return codes.empty() ? 0 : codes[0].rows; }
  int cols() const { return codes.empty() ? 0 : codes[0].cols; }
  std::size_t size() const { return codes.size(); }
};

// Reads a view's brackets with OpenCV (PNG/JPEG 8-bit, TIFF/PNG 16-bit; grey images become three
// equal channels) or LibRaw (RAW files, by extension: is_raw_file), and their exposures
// (resolve_exposure; for RAW files the file's own shutter, ISO and aperture fill what
// photoset.yaml leaves out, source "raw"). Every RAW bracket of the view is developed with the
// white balance of its first listed bracket, so the brackets share one colour scale.
// fit_sizes: files whose sizes differ (hand-cropped brackets) by at most 10% a side are centred on
// the middle bracket's frame, padded with their median code and marked uncovered there, for
// align_brackets to register; without it, or beyond 10%, differing sizes are an error. Throws
// std::runtime_error naming the file for unreadable images, other depths, mixed sizes or depths,
// RAW mixed with other files, or two brackets with the same exposure.
BracketSet load_brackets(const PhotoView& view, bool fit_sizes = false);

// Builds a set from in-memory images (CV_8UC3 or CV_16UC3, RGB) and exposures; sorts by exposure.
// Same checks as load_brackets. For tests and benchmarks (lossy: the images went through JPEG).
BracketSet make_brackets(std::vector<cv::Mat> images, std::vector<double> exposures,
                         std::vector<std::string> names = {}, bool lossy = false);

}  // namespace rsibr
