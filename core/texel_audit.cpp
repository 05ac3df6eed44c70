#include "core/texel_audit.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace rsibr {

TexelAudit audit_texels(const cv::Mat& m) {
  if (m.depth() != CV_32F) throw std::logic_error("audit_texels: expected a float image");
  TexelAudit a;
  const int ch = m.channels();
  for (int r = 0; r < m.rows; ++r) {
    const float* p = m.ptr<float>(r);
    for (int i = 0; i < m.cols * ch; ++i) {
      const float x = p[i];
      const bool nan = std::isnan(x), inf = std::isinf(x), huge = !nan && !inf && std::abs(x) > kMaxRadiance;
      a.nan += nan;
      a.inf += inf;
      a.huge += huge;
      a.negative += !nan && !inf && !huge && x < 0;
      if ((nan || inf || huge) && a.first_row < 0) a.first_row = r, a.first_col = i / ch;
    }
  }
  return a;
}

std::string TexelAudit::describe() const {
  std::ostringstream s;
  std::string sep;
  const auto part = [&](long n, const std::string& what) {
    if (n == 0) return;
    s << sep << n << " " << what;
    sep = ", ";
  };
  part(nan, "NaN");
  part(inf, "Inf");
  std::ostringstream beyond;
  beyond << "values beyond " << kMaxRadiance;
  part(huge, beyond.str());
  if (first_row >= 0) s << " (the first at texel column " << first_col << ", row " << first_row << ")";
  return s.str();
}

namespace {

// One channel (CV_32FC1). The window sums are unnormalised box filters (reflected at the border).
//   ask_x   = d_x / S_P(x)           the share of its window's positive mass deficit x needs
//   take_y  = min(P_y, P_y * sum_{x in W(y)} ask_x)
// and every deficit is then scaled by 1 - (sum take) / (sum of the deficits that had positive mass
// in their window): the channel's sum is exact, the attribution to windows approximate.
void remove_negative_ringing_channel(cv::Mat& c) {
  cv::Mat positive = cv::max(c, 0.0), deficit = cv::max(-c, 0.0);
  const int largest = std::max(c.rows, c.cols);
  for (int radius = 1;; radius *= 2) {
    if (cv::countNonZero(deficit) == 0) break;
    const cv::Size window(2 * radius + 1, 2 * radius + 1);
    cv::Mat window_positive;
    cv::boxFilter(positive, window_positive, CV_64F, window, cv::Point(-1, -1), false, cv::BORDER_REFLECT);
    cv::Mat deficit64;
    deficit.convertTo(deficit64, CV_64F);
    cv::Mat ask = cv::Mat::zeros(c.size(), CV_64F);
    double asked = 0;
    for (int r = 0; r < c.rows; ++r) {
      const double* d = deficit64.ptr<double>(r);
      const double* s = window_positive.ptr<double>(r);
      double* a = ask.ptr<double>(r);
      for (int i = 0; i < c.cols; ++i)
        if (d[i] > 0 && s[i] > 0) a[i] = d[i] / s[i], asked += d[i];
    }
    cv::Mat pull;
    cv::boxFilter(ask, pull, CV_64F, window, cv::Point(-1, -1), false, cv::BORDER_REFLECT);
    double taken = 0;
    for (int r = 0; r < c.rows; ++r) {
      float* p = positive.ptr<float>(r);
      const double* q = pull.ptr<double>(r);
      for (int i = 0; i < c.cols; ++i) {
        const double t = std::min(double(p[i]), double(p[i]) * q[i]);
        p[i] = float(double(p[i]) - t);
        taken += t;
      }
    }
    const double kept = asked > 0 ? std::clamp(1.0 - taken / asked, 0.0, 1.0) : 1.0;
    for (int r = 0; r < c.rows; ++r) {
      float* d = deficit.ptr<float>(r);
      const double* a = ask.ptr<double>(r);
      for (int i = 0; i < c.cols; ++i)
        if (a[i] > 0) d[i] = kept > 1e-6 ? float(d[i] * kept) : 0.f;
    }
    if (radius >= largest) break;  // what is left has no positive mass anywhere: dropped
  }
  c = positive;
}

}  // namespace

long remove_negative_ringing(cv::Mat& m) {
  if (m.depth() != CV_32F) throw std::logic_error("remove_negative_ringing: expected a float image");
  long negative = 0;
  for (int r = 0; r < m.rows; ++r) {
    const float* p = m.ptr<float>(r);
    for (int i = 0; i < m.cols * m.channels(); ++i) negative += p[i] < 0;
  }
  if (negative == 0) return 0;
  std::vector<cv::Mat> channels;
  cv::split(m, channels);
  for (cv::Mat& c : channels) remove_negative_ringing_channel(c);
  cv::merge(channels, m);
  return negative;
}

long sanitize_texels(cv::Mat& m) {
  if (m.depth() != CV_32F) throw std::logic_error("sanitize_texels: expected a float image");
  long changed = 0;
  const int ch = m.channels();
  for (int r = 0; r < m.rows; ++r) {
    float* p = m.ptr<float>(r);
    for (int i = 0; i < m.cols * ch; ++i)
      if (!std::isfinite(p[i]) || p[i] > kMaxRadiance) {
        p[i] = 0.f;
        ++changed;
      }
  }
  return changed + remove_negative_ringing(m);
}

}  // namespace rsibr
