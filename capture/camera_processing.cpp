#include "capture/camera_processing.h"

#include "core/parallel.h"
#include "formats/image_codecs.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace rsibr {

Vec3 CameraProcessing::gains() const {
  if (white_balance) return *white_balance;
  return Vec3::Constant(sensitivity.maxCoeff()).cwiseQuotient(sensitivity);
}

Mat3 CameraProcessing::matrix() const {
  if (colour_matrix) return *colour_matrix;
  const Vec3 y(0.2126, 0.7152, 0.0722);
  return saturation * Mat3::Identity() + (1 - saturation) * Vec3::Ones() * y.transpose();
}

cv::Mat process_raw(const cv::Mat& raw, const CameraProcessing& p, const CameraResponse& response, int max_code) {
  if (raw.type() != CV_64FC3) throw std::invalid_argument("process_raw: raw must be CV_64FC3");
  const Vec3 g = p.gains();
  const Mat3 M = p.matrix();
  // round(f(m) * max_code) = #{i : m >= f^-1((i + 1/2) / max_code)} (f increasing): thresholds once.
  std::vector<std::vector<double>> thresholds(3);
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < max_code; ++i) thresholds[std::size_t(c)].push_back(response.relative((i + 0.5) / max_code, c));
  cv::Mat out(raw.rows, raw.cols, CV_16UC3);
  parallel_for_rows(raw.rows, [&](int y) {
    const double* r = raw.ptr<double>(y);
    std::uint16_t* o = out.ptr<std::uint16_t>(y);
    for (int x = 0; x < raw.cols; ++x) {
      Vec3 w;
      for (int c = 0; c < 3; ++c) w[c] = std::min(1.0, g[c] * r[3 * x + c]);
      const Vec3 m = M * w;
      for (int c = 0; c < 3; ++c) {
        const double v = std::clamp(m[c], 0.0, 1.0);
        const auto& t = thresholds[std::size_t(c)];
        o[3 * x + c] = std::uint16_t(std::upper_bound(t.begin(), t.end(), v) - t.begin());
      }
    }
  });
  return out;
}

cv::Mat linear_output(const cv::Mat& radiance, const CameraProcessing& p) {
  if (radiance.type() != CV_32FC3) throw std::invalid_argument("linear_output: radiance must be CV_32FC3");
  const Mat3 A = p.matrix() * p.gains().cwiseProduct(p.sensitivity).asDiagonal();
  cv::Mat out(radiance.size(), CV_32FC3);
  for (int y = 0; y < radiance.rows; ++y) {
    const float* in = radiance.ptr<float>(y);
    float* o = out.ptr<float>(y);
    for (int x = 0; x < radiance.cols; ++x) {
      const Vec3 v = A * Vec3(in[3 * x], in[3 * x + 1], in[3 * x + 2]);
      for (int c = 0; c < 3; ++c) o[3 * x + c] = float(v[c]);
    }
  }
  return out;
}

cv::Mat jpeg_compress(const cv::Mat& codes, int quality) {
  if (quality < 1 || quality > 100) throw std::invalid_argument("jpeg_compress: quality must be 1..100");
  if (codes.channels() != 3) throw std::invalid_argument("jpeg_compress: three channels expected");
  cv::Mat eight, bgr;
  codes.convertTo(eight, CV_8U);
  cv::cvtColor(eight, bgr, cv::COLOR_RGB2BGR);
  std::vector<uchar> bytes;
  if (!encode_image(".jpg", bgr, bytes, {cv::IMWRITE_JPEG_QUALITY, quality}))
    throw std::runtime_error("jpeg_compress: the encoder failed");
  const cv::Mat back = decode_image(bytes, cv::IMREAD_COLOR);
  cv::Mat rgb, out;
  cv::cvtColor(back, rgb, cv::COLOR_BGR2RGB);
  rgb.convertTo(out, CV_16UC3);
  return out;
}

cv::Mat camera_bracket(const cv::Mat& radiance, double e, const SensorNoise& noise, const CameraProcessing& p,
                       const CameraResponse& response, int max_code, int jpeg_quality, std::uint64_t seed,
                       std::uint64_t stream) {
  if (jpeg_quality > 0 && max_code != 255) throw std::invalid_argument("camera_bracket: JPEG needs 8-bit codes");
  cv::Mat codes = process_raw(expose_raw(radiance, e, noise, p.sensitivity, seed, stream), p, response, max_code);
  return jpeg_quality > 0 ? jpeg_compress(codes, jpeg_quality) : codes;
}

}  // namespace rsibr
