#include "hdr/alignment.h"

#include <opencv2/imgproc.hpp>
#include <opencv2/photo.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rsibr {
namespace {

// A moved bracket accepts its shift only when it removes this much of the disagreement, measured
// on at least this fraction of the frame (a bracket white or black almost everywhere has no
// bitmap to compare, and MTB's shift for it is noise).
constexpr double kAcceptRatio = 0.8;
constexpr double kMinCompared = 0.01;

// Fraction of pixels compared (outside both exclusion bitmaps, inside both coverages) where the
// threshold bitmaps of a and of b moved by `shift` disagree; the compared count in `compared`.
double mismatch(const cv::Mat& tb_a, const cv::Mat& eb_a, const cv::Mat& tb_b, const cv::Mat& eb_b, cv::Point shift,
                int* compared = nullptr) {
  const cv::Mat M = (cv::Mat_<double>(2, 3) << 1, 0, shift.x, 0, 1, shift.y);
  cv::Mat tb, eb;
  cv::warpAffine(tb_b, tb, M, tb_b.size(), cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::warpAffine(eb_b, eb, M, eb_b.size(), cv::INTER_NEAREST, cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::Mat both = eb & eb_a, diff;
  cv::bitwise_xor(tb, tb_a, diff);
  diff &= both;
  const int n = cv::countNonZero(both);
  if (compared) *compared = n;
  return n > 0 ? double(cv::countNonZero(diff)) / n : 0.0;
}

cv::Mat shifted(const cv::Mat& m, cv::Point s, int border, const cv::Scalar& fill = cv::Scalar()) {
  const cv::Mat M = (cv::Mat_<double>(2, 3) << 1, 0, s.x, 0, 1, s.y);
  cv::Mat out;
  cv::warpAffine(m, out, M, m.size(), cv::INTER_NEAREST, border, fill);
  return out;
}

}  // namespace

const char* to_string(Alignment a) {
  switch (a) {
    case Alignment::off: return "off";
    case Alignment::automatic: return "auto";
    case Alignment::always: return "on";
  }
  return "?";
}

Alignment parse_alignment(const std::string& s) {
  if (s == "off") return Alignment::off;
  if (s == "auto") return Alignment::automatic;
  if (s == "on") return Alignment::always;
  throw std::invalid_argument("alignment '" + s + "': expected auto, on or off");
}

AlignmentResult align_brackets(BracketSet& b, Alignment mode, int max_bits) {
  const std::size_t P = b.size();
  AlignmentResult res;
  res.shifts.assign(P, cv::Point(0, 0));
  res.found.assign(P, cv::Point(0, 0));
  res.mismatch_before.assign(P, 0.0);
  res.mismatch_after.assign(P, 0.0);
  if (P < 2 || mode == Alignment::off) return res;
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
  // Under 32 px a side there is no pyramid to search (and OpenCV's MTB crashes without one).
  if (bits == 0) return res;
  auto mtb = cv::createAlignMTB(bits, 4, true);
  std::vector<cv::Mat> tb(P), eb(P);
  for (std::size_t j = 0; j < P; ++j) {
    mtb->computeBitmaps(grey[j], tb[j], eb[j]);
    if (j < b.covered.size() && !b.covered[j].empty()) eb[j] &= b.covered[j];  // padding is no evidence
  }
  for (std::size_t j = 0; j < P; ++j) {
    if (j == mid) continue;
    // calculateShift(img0, img1) is the shift that moves img1 onto img0.
    const cv::Point s = mtb->calculateShift(grey[mid], grey[j]);
    res.found[j] = s;
    int n0 = 0, n1 = 0;
    res.mismatch_before[j] = mismatch(tb[mid], eb[mid], tb[j], eb[j], cv::Point(0, 0), &n0);
    res.mismatch_after[j] =
        s == cv::Point(0, 0) ? res.mismatch_before[j] : mismatch(tb[mid], eb[mid], tb[j], eb[j], s, &n1);
    if (s == cv::Point(0, 0)) continue;
    const double enough = kMinCompared * double(b.rows()) * double(b.cols());
    // Disagreeing pixels before and after: the drop must also stand out of their counting noise
    // (small or mostly white frames give a few dozen, and MTB picks the shift that happens to
    // lower them).
    const double d0 = res.mismatch_before[j] * n0, d1 = res.mismatch_after[j] * n1;
    const bool better = double(n0) >= enough && double(n1) >= enough && res.mismatch_before[j] > 0 &&
                        res.mismatch_after[j] <= kAcceptRatio * res.mismatch_before[j] &&
                        d0 - d1 > 4.0 * std::sqrt(d0 + d1) + 20.0;
    if (mode == Alignment::automatic && !b.fitted_sizes && !better) continue;
    res.shifts[j] = s;
    b.codes[j] = shifted(b.codes[j], s, cv::BORDER_REPLICATE);
    if (j < b.saturated.size() && !b.saturated[j].empty())
      b.saturated[j] = shifted(b.saturated[j], s, cv::BORDER_REPLICATE);
    if (b.covered.size() < P) b.covered.resize(P);
    const cv::Mat cov = b.covered[j].empty() ? cv::Mat(b.codes[j].size(), CV_8UC1, cv::Scalar(255)) : b.covered[j];
    b.covered[j] = shifted(cov, s, cv::BORDER_CONSTANT, cv::Scalar(0));
  }
  return res;
}

}  // namespace rsibr
