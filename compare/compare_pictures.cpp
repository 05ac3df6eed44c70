#include "compare/compare_pictures.h"

#include "core/colour.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace rsibr {
namespace {

const cv::Scalar kBackground(32, 32, 32);
const cv::Scalar kText(230, 230, 230);
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kFontScale = 0.45;
constexpr int kGap = 6, kStrip = 22;

std::string number_text(double v) {
  std::ostringstream s;
  s << std::setprecision(3) << v;
  return s.str();
}

void put_text(cv::Mat& img, const std::string& text, int x, int baseline_y) {
  cv::putText(img, text, cv::Point(x, baseline_y), kFont, kFontScale, kText, 1, cv::LINE_AA);
}

int text_width(const std::string& text) {
  int base = 0;
  return cv::getTextSize(text, kFont, kFontScale, 1, &base).width;
}

// Magnifies by an integer factor (nearest texel: texels stay visible), or shrinks by area
// averaging so that the longer side is at most max_side.
cv::Mat fit_panel(const cv::Mat& img, int factor, int max_side) {
  cv::Mat out;
  if (std::max(img.cols, img.rows) > max_side) {
    const double s = double(max_side) / std::max(img.cols, img.rows);
    cv::resize(img, out, cv::Size(std::max(1, int(img.cols * s)), std::max(1, int(img.rows * s))), 0, 0,
               cv::INTER_AREA);
    return out;
  }
  if (factor <= 1) return img;
  cv::resize(img, out, cv::Size(img.cols * factor, img.rows * factor), 0, 0, cv::INTER_NEAREST);
  return out;
}

}  // namespace

cv::Mat heat_map_bgr(const cv::Mat& error, const cv::Mat& weight, double max) {
  if (error.type() != CV_32FC1 || weight.type() != CV_32FC1 || error.size() != weight.size())
    throw std::invalid_argument("heat map: error and weight must be CV_32FC1 of one size");
  if (!(max > 0) || !std::isfinite(max)) throw std::invalid_argument("heat map: the scale must be positive and finite");
  cv::Mat index(error.size(), CV_8UC1);
  for (int r = 0; r < error.rows; ++r) {
    const float* e = error.ptr<float>(r);
    uchar* o = index.ptr<uchar>(r);
    for (int c = 0; c < error.cols; ++c) {
      const double v = std::isfinite(e[c]) ? std::clamp(double(e[c]) / max, 0.0, 1.0) : 1.0;
      o[c] = uchar(std::lround(255 * v));
    }
  }
  cv::Mat out;
  cv::applyColorMap(index, out, cv::COLORMAP_VIRIDIS);
  for (int r = 0; r < error.rows; ++r) {
    const float* w = weight.ptr<float>(r);
    for (int c = 0; c < error.cols; ++c)
      if (!(w[c] > 0)) out.at<cv::Vec3b>(r, c) = kNoWeightColour;
  }
  return out;
}

cv::Mat colour_bar_bgr(int width, int height) {
  cv::Mat index(std::max(1, height), std::max(1, width), CV_8UC1);
  for (int c = 0; c < index.cols; ++c)
    index.col(c).setTo(cv::Scalar(std::lround(255.0 * c / std::max(1, index.cols - 1))));
  cv::Mat out;
  cv::applyColorMap(index, out, cv::COLORMAP_VIRIDIS);
  return out;
}

double heat_scale_max(const std::vector<cv::Mat>& errors, const std::vector<cv::Mat>& weights, double q,
                      double min_max) {
  std::vector<float> values;
  for (std::size_t i = 0; i < errors.size(); ++i)
    for (int r = 0; r < errors[i].rows; ++r) {
      const float* e = errors[i].ptr<float>(r);
      const float* w = weights[i].ptr<float>(r);
      for (int c = 0; c < errors[i].cols; ++c)
        if (w[c] > 0 && std::isfinite(e[c])) values.push_back(e[c]);
    }
  if (values.empty()) return min_max;
  const std::size_t k = std::min(values.size() - 1, std::size_t(std::floor(q * double(values.size() - 1) + 0.5)));
  std::nth_element(values.begin(), values.begin() + long(k), values.end());
  const double v = values[k];
  if (!(v > min_max)) return min_max;
  // Round up to 1, 2 or 5 x 10^k.
  const double decade = std::pow(10.0, std::floor(std::log10(v)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (v <= m * decade * (1 + 1e-12)) return m * decade;
  return 10 * decade;
}

cv::Mat side_by_side(const SideBySideInput& in, int min_panel, int max_panel) {
  const int w = in.a_rgb.cols, h = in.a_rgb.rows;
  const int factor = std::max(1, (min_panel + std::max(w, h) - 1) / std::max(w, h));
  const cv::Mat a = fit_panel(display_encode(in.a_rgb, in.exposure_stops), factor, max_panel);
  const cv::Mat b = fit_panel(display_encode(in.b_rgb, in.exposure_stops), factor, max_panel);
  const cv::Mat heat = fit_panel(heat_map_bgr(in.error, in.weight, in.heat_max), factor, max_panel);
  const int pw = a.cols, ph = a.rows;
  const int bar_h = 12, ticks_h = 18;
  const int width = 3 * pw + 4 * kGap;
  const int height = kStrip + kStrip + ph + kGap + bar_h + ticks_h + kGap;
  cv::Mat out(height, width, CV_8UC3, kBackground);
  put_text(out, in.title, kGap, kStrip - 6);
  const int y0 = 2 * kStrip;
  const std::string labels[3] = {in.a_label, in.b_label, in.heat_label + " (" + in.unit + ")"};
  const cv::Mat* panels[3] = {&a, &b, &heat};
  for (int i = 0; i < 3; ++i) {
    const int x0 = kGap + i * (pw + kGap);
    put_text(out, labels[i], x0, y0 - 6);
    panels[i]->copyTo(out(cv::Rect(x0, y0, pw, ph)));
  }
  // Scale bar under the heat map, with its tick values.
  const int hx = kGap + 2 * (pw + kGap), by = y0 + ph + kGap;
  colour_bar_bgr(pw, bar_h).copyTo(out(cv::Rect(hx, by, pw, bar_h)));
  const double ticks[3] = {0.0, 0.5 * in.heat_max, in.heat_max};
  for (int i = 0; i < 3; ++i) {
    const std::string t = number_text(ticks[i]);
    const int tx =
        std::clamp(hx + int(std::lround(i * 0.5 * (pw - 1))) - text_width(t) / 2, hx, hx + pw - text_width(t));
    put_text(out, t, tx, by + bar_h + ticks_h - 5);
  }
  return out;
}

cv::Mat contact_sheet(const std::vector<cv::Mat>& panels, int thumb_width) {
  if (panels.empty()) return cv::Mat(1, 1, CV_8UC3, kBackground);
  const int n = int(panels.size());
  const int columns = int(std::ceil(std::sqrt(double(n))));
  const int rows = (n + columns - 1) / columns;
  std::vector<cv::Mat> thumbs;
  int thumb_h = 0;
  for (const cv::Mat& p : panels) {
    cv::Mat t;
    const double s = double(thumb_width) / p.cols;
    cv::resize(p, t, cv::Size(thumb_width, std::max(1, int(std::lround(p.rows * s)))), 0, 0,
               s < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
    thumb_h = std::max(thumb_h, t.rows);
    thumbs.push_back(t);
  }
  cv::Mat out(rows * (thumb_h + kGap) + kGap, columns * (thumb_width + kGap) + kGap, CV_8UC3, kBackground);
  for (int i = 0; i < n; ++i) {
    const int x = kGap + (i % columns) * (thumb_width + kGap), y = kGap + (i / columns) * (thumb_h + kGap);
    thumbs[std::size_t(i)].copyTo(out(cv::Rect(x, y, thumb_width, thumbs[std::size_t(i)].rows)));
  }
  return out;
}

}  // namespace rsibr
