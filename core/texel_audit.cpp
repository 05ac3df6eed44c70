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

// One channel (CV_32FC1). With window W of radius r, positive values P and deficits d (-L where
// L < 0), over unnormalised box sums (reflected at the border, which keeps them symmetric:
// y in W(x) exactly when x in W(y)):
//   ask_x = d_x / sum_{y in W(x)} P_y        the share of its window's positive mass x needs
//   q_y   = sum_{x in W(y)} ask_x            what is asked of y, as a fraction of P_y
//   h_y   = min(1, 1 / q_y)                  the fraction of the asks y can honour
//   y gives P_y min(q_y, 1);  x receives ask_x sum_{y in W(x)} P_y h_y
// so what the positives give equals what the deficits receive, texel by texel of the windows, and
// each channel's sum is kept. Deficits left over (their window had too little) try the next,
// doubled radius. Only the deficits' bounding box, grown by 2r, is filtered.
void remove_negative_ringing_channel(cv::Mat& c) {
  cv::Mat positive = cv::max(c, 0.0), deficit = cv::max(-c, 0.0);
  const int largest = std::max(c.rows, c.cols);
  for (int radius = 1;; radius *= 2) {
    cv::Mat has_deficit = deficit > 0;
    if (cv::countNonZero(has_deficit) == 0) break;
    if (radius > 2 * largest) {  // no positive value anywhere can absorb what is left
      deficit.setTo(0);
      break;
    }
    const cv::Rect box = cv::boundingRect(has_deficit);
    const cv::Rect roi =
        cv::Rect(box.x - 2 * radius, box.y - 2 * radius, box.width + 4 * radius, box.height + 4 * radius) &
        cv::Rect(0, 0, c.cols, c.rows);
    cv::Mat p = positive(roi), d = deficit(roi);
    const cv::Size window(2 * radius + 1, 2 * radius + 1);
    const auto box_sum = [&](const cv::Mat& in) {
      cv::Mat out;
      cv::boxFilter(in, out, CV_64F, window, cv::Point(-1, -1), false, cv::BORDER_REFLECT);
      return out;
    };
    cv::Mat p64, d64;
    p.convertTo(p64, CV_64F);
    d.convertTo(d64, CV_64F);
    const cv::Mat window_positive = box_sum(p64);
    cv::Mat ask = cv::Mat::zeros(roi.size(), CV_64F);
    for (int r = 0; r < roi.height; ++r)
      for (int i = 0; i < roi.width; ++i)
        if (d64.at<double>(r, i) > 0 && window_positive.at<double>(r, i) > 0)
          ask.at<double>(r, i) = d64.at<double>(r, i) / window_positive.at<double>(r, i);
    const cv::Mat asked = box_sum(ask);
    cv::Mat honoured(roi.size(), CV_64F);  // P_y h_y
    for (int r = 0; r < roi.height; ++r)
      for (int i = 0; i < roi.width; ++i) {
        const double q = asked.at<double>(r, i), pv = p64.at<double>(r, i);
        honoured.at<double>(r, i) = q > 1 ? pv / q : pv;
        p.at<float>(r, i) = float(pv - pv * std::min(q, 1.0));
      }
    const cv::Mat supply = box_sum(honoured);
    for (int r = 0; r < roi.height; ++r)
      for (int i = 0; i < roi.width; ++i) {
        const double a = ask.at<double>(r, i);
        if (a <= 0) continue;
        const double left = d64.at<double>(r, i) - a * supply.at<double>(r, i);
        // Rounding leaves crumbs of a deficit that was met in full: dropped, not chased.
        d.at<float>(r, i) = left > 1e-6 * d64.at<double>(r, i) ? float(left) : 0.f;
      }
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
