// Environments and helpers shared by the integrator tests.
#pragma once

#include "bake/integrator.h"
#include "core/patterns.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace rsibr::test {

inline EnvMap latlong_env(const Radiance& f, int width = 64, int subsamples = 4) {
  return render_pattern(f, Layout(LayoutKind::LatLong, width, width / 2), subsamples);
}

// Smooth, coloured, with energy in every SH band (a soft lobe plus a gradient).
inline Radiance smooth_radiance() {
  return [](const Vec3& d) {
    const Vec3 a = Vec3(0.4, 0.7, -0.3).normalized();
    const double lobe = std::exp(4.0 * (d.dot(a) - 1.0));
    return Vec3(0.6 + 0.3 * d.y() + 2.0 * lobe, 0.5 + 0.2 * d.x() * d.z() + 1.5 * lobe, 0.4 - 0.2 * d.y() + lobe);
  };
}

// A sky with a disc sun of 1e5 x the zenith radiance (1.5 degrees radius, so a 64 x 32 texel
// still sees ~1/4 of the sun's peak: ~2e4 x the sky).
inline Radiance sunny_radiance(double sun = 1e5) {
  return patterns::sun_and_sky(Vec3(0.3, 0.6, -0.5), 1.5 * kPi / 180, Vec3::Constant(sun), Vec3(0.25, 0.45, 1.0),
                               Vec3(0.9, 0.9, 0.85));
}

// Relative RMS error of a against b over texels where b is non-zero (all channels).
inline double relative_rms(const cv::Mat& a, const cv::Mat& b) {
  double num = 0, den = 0;
  for (int r = 0; r < a.rows; ++r)
    for (int c = 0; c < a.cols; ++c)
      for (int k = 0; k < 3; ++k) {
        const double x = a.at<cv::Vec3f>(r, c)[k], y = b.at<cv::Vec3f>(r, c)[k];
        num += (x - y) * (x - y);
        den += y * y;
      }
  return std::sqrt(num / den);
}

// Mean over texels inside the disc, per channel summed.
inline double map_mean(const cv::Mat& m) {
  const cv::Scalar s = cv::sum(m);
  return (s[0] + s[1] + s[2]) / (3.0 * m.rows * m.cols);
}

inline bool all_finite_nonnegative(const cv::Mat& m) {
  for (int r = 0; r < m.rows; ++r)
    for (int c = 0; c < m.cols; ++c)
      for (int k = 0; k < 3; ++k) {
        const float v = m.at<cv::Vec3f>(r, c)[k];
        if (!std::isfinite(v) || v < 0) return false;
      }
  return true;
}

}  // namespace rsibr::test
