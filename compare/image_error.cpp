#include "compare/image_error.h"

#include "core/parallel.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace rsibr {

void ErrorSums::merge(const ErrorSums& o) {
  weight += o.weight;
  texels += o.texels;
  squared_error += o.squared_error;
  squared_reference += o.squared_reference;
  squared_log += o.squared_log;
  for (int c = 0; c < 3; ++c) {
    sum_a[std::size_t(c)] += o.sum_a[std::size_t(c)];
    sum_b[std::size_t(c)] += o.sum_b[std::size_t(c)];
  }
}

namespace {

void check_inputs(const cv::Mat& a, const cv::Mat& b, const cv::Mat& weight) {
  if (a.type() != CV_32FC3 || b.type() != CV_32FC3 || weight.type() != CV_32FC1)
    throw std::invalid_argument("error metrics: images must be CV_32FC3 and the weight CV_32FC1");
  if (a.size() != b.size() || a.size() != weight.size())
    throw std::invalid_argument("error metrics: images and weight differ in size");
}

double log2_ratio(double a, double b, double eps) {
  return std::log2((std::max(0.0, a) + eps) / (std::max(0.0, b) + eps));
}

}  // namespace

ErrorSums error_sums(const cv::Mat& a, const cv::Mat& b, const cv::Mat& weight, const ErrorSettings& s,
                     const std::array<double, 3>& g) {
  check_inputs(a, b, weight);
  std::vector<ErrorSums> rows(std::size_t(a.rows));
  parallel_for_rows(a.rows, [&](int r) {
    ErrorSums& row = rows[std::size_t(r)];
    const float* pa = a.ptr<float>(r);
    const float* pb = b.ptr<float>(r);
    const float* pw = weight.ptr<float>(r);
    for (int x = 0; x < a.cols; ++x) {
      const double w = pw[x];
      if (!(w > 0)) continue;
      row.weight += w;
      ++row.texels;
      for (int c = 0; c < 3; ++c) {
        const double av = g[std::size_t(c)] * pa[3 * x + c], bv = pb[3 * x + c];
        const double l = log2_ratio(av, bv, s.log_epsilon);
        row.squared_error += w * (av - bv) * (av - bv);
        row.squared_reference += w * bv * bv;
        row.squared_log += w * l * l;
        row.sum_a[std::size_t(c)] += w * av;
        row.sum_b[std::size_t(c)] += w * bv;
      }
    }
  });
  ErrorSums total;
  for (const ErrorSums& row : rows) total.merge(row);
  return total;
}

ErrorMetrics error_metrics(const ErrorSums& s, const ErrorSettings& settings) {
  if (!(s.weight > 0)) throw std::invalid_argument("no texel has a non-zero weight (confidence and disc)");
  ErrorMetrics m;
  m.weight = s.weight;
  m.texels = s.texels;
  if (s.squared_reference > 0) {
    m.relative_rms = std::sqrt(s.squared_error / s.squared_reference);
  } else if (s.squared_error > 0) {
    throw std::invalid_argument(
        "the reference B is zero over every weighted texel, A is not: no scale for a relative error");
  }
  m.log_rms_stops = std::sqrt(s.squared_log / (3 * s.weight));
  m.mse = s.squared_error / (3 * s.weight);
  const double floor = std::pow(settings.psnr_peak * std::ldexp(1.0, -24), 2);
  m.psnr_capped = !(m.mse > floor);
  m.psnr_db = 10 * std::log10(settings.psnr_peak * settings.psnr_peak / std::max(m.mse, floor));
  for (int c = 0; c < 3; ++c) {
    m.mean_a[std::size_t(c)] = s.sum_a[std::size_t(c)] / s.weight;
    m.mean_b[std::size_t(c)] = s.sum_b[std::size_t(c)] / s.weight;
  }
  return m;
}

cv::Mat log_error_image(const cv::Mat& a, const cv::Mat& b, const cv::Mat& weight, double eps,
                        const std::array<double, 3>& g) {
  check_inputs(a, b, weight);
  cv::Mat out(a.size(), CV_32FC1, cv::Scalar(0));
  parallel_for_rows(a.rows, [&](int r) {
    const float* pa = a.ptr<float>(r);
    const float* pb = b.ptr<float>(r);
    const float* pw = weight.ptr<float>(r);
    float* po = out.ptr<float>(r);
    for (int x = 0; x < a.cols; ++x) {
      if (!(pw[x] > 0)) continue;
      double sum = 0;
      for (int c = 0; c < 3; ++c) {
        const double l = log2_ratio(g[std::size_t(c)] * pa[3 * x + c], pb[3 * x + c], eps);
        sum += l * l;
      }
      po[x] = float(std::sqrt(sum / 3));
    }
  });
  return out;
}

}  // namespace rsibr
