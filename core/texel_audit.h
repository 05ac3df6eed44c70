// Values a reader takes from a file are audited before any work uses them. NaN, +-Inf and absurd
// magnitudes (beyond kMaxRadiance: 10^8 such values still sum to a finite float) would make every
// blend, bake, resample or comparison that touches them NaN or Inf, so readers refuse them with
// the count and the first position, or zero them when the user asks (--sanitize).
#pragma once

#include <opencv2/core.hpp>

#include <string>

namespace rsibr {

inline constexpr float kMaxRadiance = 1e30f;

struct TexelAudit {
  long nan = 0, inf = 0, huge = 0;     // values (not texels), over every channel
  long negative = 0;                   // finite values below zero (lossy-compression ringing)
  int first_row = -1, first_col = -1;  // the first NaN, Inf or huge value's texel
  bool bad() const { return nan > 0 || inf > 0 || huge > 0; }
  // "2 NaN, 1 Inf and 3 values beyond 1e+30 (the first at texel (column 4, row 7))".
  std::string describe() const;
};

// m: a float image (CV_32F, any channel count), rows in order.
TexelAudit audit_texels(const cv::Mat& m);

// Negative values of m (CV_32F, any channel count, finite) removed without changing the sum of
// each channel: the ringing a lossy codec leaves around a bright source is a negative lobe beside
// a positive one, so zeroing the negatives adds the negative lobe's energy back as light.
// Each negative value's deficit is taken from the positive values near it instead, in proportion
// to them, over square windows of radius 1, 2, 4, ... texels until none is left (or the window
// spans the image; what no positive value can absorb is then zeroed). Texel solid angles differ
// little within a window, so an environment's integral moves by the variation of solid angle
// across the ringing's width, not by the ringing's energy. Returns how many values were negative.
// The step at each radius runs over the deficits' windows (sparse: cost per deficit) or box
// filters over their bounding box (dense: cost per texel of the box), whichever costs less; both
// give the same values up to rounding (Auto). The others force one, for tests.
enum class FoldMethod { Auto, Sparse, Dense };
long remove_negative_ringing(cv::Mat& m, FoldMethod method = FoldMethod::Auto);

// NaN, Inf and huge values of m (CV_32F) zeroed, then its negatives removed by
// remove_negative_ringing; returns how many values it changed.
long sanitize_texels(cv::Mat& m);

}  // namespace rsibr
