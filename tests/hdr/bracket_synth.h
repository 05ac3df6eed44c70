// Test-only bracket synthesizer (the project's capture/ renderer is built separately): a known
// radiance image, the shared exposure convention X = L * e * k, Poisson shot noise (full_well
// photo-electrons at X = 1), Gaussian read noise (sigma in X units), clipping to [0, 1], and a
// per-channel response u_c(X) quantised to 8- or 16-bit codes. Seeded: same seed, same codes.
#pragma once

#include "hdr/bracket_set.h"

#include <opencv2/core.hpp>

#include <cmath>
#include <functional>
#include <random>
#include <vector>

namespace rsibr::testing {

struct BracketCamera {
  std::function<double(int channel, double X)> response = [](int, double X) { return X; };  // [0,1] -> [0,1]
  double gain = 1.0;                                                                        // k
  double full_well = 2e4;  // electrons at X = 1 (0: no shot noise)
  double read_sigma = 1.5e-4;
  int max_code = 65535;
  double shot() const { return full_well > 0 ? 1.0 / full_well : 0.0; }
  double read() const { return read_sigma * read_sigma; }
};

// radiance: CV_64FC3 (or CV_32FC3), RGB. Returns RGB codes, CV_16UC3 or CV_8UC3.
inline std::vector<cv::Mat> synthesize(const cv::Mat& radiance, const std::vector<double>& exposures,
                                       const BracketCamera& cam, unsigned seed) {
  cv::Mat L;
  radiance.convertTo(L, CV_64FC3);
  std::vector<cv::Mat> out;
  for (std::size_t j = 0; j < exposures.size(); ++j) {
    std::mt19937_64 rng(seed * 1000003ull + j);
    std::normal_distribution<double> gauss(0.0, 1.0);
    cv::Mat codes(L.size(), cam.max_code == 255 ? CV_8UC3 : CV_16UC3);
    for (int r = 0; r < L.rows; ++r)
      for (int x = 0; x < L.cols; ++x)
        for (int c = 0; c < 3; ++c) {
          const double X = L.at<cv::Vec3d>(r, x)[c] * exposures[j] * cam.gain;
          double Xn = X;
          if (cam.full_well > 0) {
            const double mean = X * cam.full_well;
            double electrons;
            if (mean > 1e5)
              electrons = mean + std::sqrt(mean) * gauss(rng);  // Poisson ~ normal; past saturation anyway
            else
              electrons = double(std::poisson_distribution<long>(mean)(rng));
            Xn = electrons / cam.full_well;
          }
          Xn += cam.read_sigma * gauss(rng);
          Xn = std::clamp(Xn, 0.0, 1.0);
          const double code = std::round(std::clamp(cam.response(c, Xn), 0.0, 1.0) * cam.max_code);
          if (cam.max_code == 255)
            codes.at<cv::Vec3b>(r, x)[c] = static_cast<unsigned char>(code);
          else
            codes.at<cv::Vec3w>(r, x)[c] = static_cast<std::uint16_t>(code);
        }
    out.push_back(codes);
  }
  return out;
}

// Exposures e_0 * ratio^j, j = 0..n-1.
inline std::vector<double> exposure_series(double e0, double ratio, int n) {
  std::vector<double> e;
  for (int j = 0; j < n; ++j) e.push_back(e0 * std::pow(ratio, j));
  return e;
}

// A smooth test scene: log-radiance ramps from 10^lo to 10^hi left to right, with a gentle
// vertical colour tilt so the three channels differ (values are L * k-free scene radiance).
inline cv::Mat ramp_scene(int rows, int cols, double lo, double hi) {
  cv::Mat L(rows, cols, CV_64FC3);
  for (int r = 0; r < rows; ++r)
    for (int x = 0; x < cols; ++x) {
      const double v = std::pow(10.0, lo + (hi - lo) * (x + 0.5) / cols);
      const double t = double(r) / std::max(1, rows - 1);
      L.at<cv::Vec3d>(r, x) = cv::Vec3d(v * (0.8 + 0.4 * t), v, v * (1.2 - 0.4 * t));
    }
  return L;
}

// A film-like S-shaped, per-channel response (monotone, not a power law).
inline double s_curve(int c, double X) {
  const double t = std::pow(X, 1.0 / (2.0 + 0.2 * c));
  return 0.6 * t + 0.4 * t * t * (3 - 2 * t);
}

}  // namespace rsibr::testing
