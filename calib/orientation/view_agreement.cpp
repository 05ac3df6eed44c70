#include "calib/orientation/view_agreement.h"

#include "calib/orientation/ball_cube_features.h"
#include "hdr/merge.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

namespace rsibr {

namespace {

// The weighted median of (value, weight) pairs.
double weighted_median(std::vector<std::pair<double, double>> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  double total = 0;
  for (const auto& p : v) total += p.second;
  double acc = 0;
  for (const auto& p : v)
    if ((acc += p.second) >= 0.5 * total) return p.first;
  return v.back().first;
}

// The luminance the view shows in camera-frame direction r, or nullopt where it does not show it
// cleanly (the nearest pixel's flags: clipped, outside the photo).
std::optional<double> luminance_toward(const ViewImage& view, const BallCone& cone, const LensModel& lens,
                                       const BallFeatureOptions& fo, const Vec3& r) {
  const auto p = ball_pixel_of(lens, cone, fo, r, false);
  if (!p) return std::nullopt;
  const int x = std::clamp(int(std::lround(p->pixel.x())), 0, view.radiance.cols - 1);
  const int y = std::clamp(int(std::lround(p->pixel.y())), 0, view.radiance.rows - 1);
  if (!view.flags.empty() && (view.flags.at<unsigned char>(y, x) & (kClipped | kOutside | kGhost))) return std::nullopt;
  const cv::Vec3f c = view.radiance.at<cv::Vec3f>(y, x);
  const double l = (double(c[0]) + c[1] + c[2]) / 3;
  if (!(l > 0) || !std::isfinite(l)) return std::nullopt;
  return l;
}

}  // namespace

ViewAgreement view_agreement(const ViewImage& a, const BallCone& cone_a, const Mat3& world_from_a, const ViewImage& b,
                             const BallCone& cone_b, const Mat3& world_from_b, const LensModel& lens,
                             const AgreementOptions& options) {
  for (const ViewImage* v : {&a, &b})
    if (v->radiance.type() != CV_32FC3 || v->radiance.cols != lens.width() || v->radiance.rows != lens.height())
      throw std::invalid_argument("view agreement: the views must be float RGB of the lens model's size");
  if (options.width < 4 || options.width % 2) throw std::invalid_argument("view agreement: width must be even, >= 4");
  BallFeatureOptions fo;
  fo.max_radius_fraction = options.max_radius_fraction;
  fo.camera_mask_deg = options.camera_mask_deg;
  const int w = options.width, h = w / 2;
  std::vector<std::pair<double, double>> ratios;
  double seen = 0, sphere = 0;
  for (int v = 0; v < h; ++v) {
    const double theta = kPi * (v + 0.5) / h, area = std::sin(theta);
    for (int u = 0; u < w; ++u) {
      const double phi = 2 * kPi * (u + 0.5) / w;
      const Vec3 d(std::sin(theta) * std::sin(phi), std::cos(theta), std::sin(theta) * std::cos(phi));
      sphere += area;
      const auto la = luminance_toward(a, cone_a, lens, fo, world_from_a.transpose() * d);
      if (!la) continue;
      const auto lb = luminance_toward(b, cone_b, lens, fo, world_from_b.transpose() * d);
      if (!lb) continue;
      ratios.push_back({std::log2(*la / *lb), area});
      seen += area;
    }
  }
  ViewAgreement out;
  out.samples = static_cast<int>(ratios.size());
  if (ratios.empty()) return out;
  out.overlap = seen / sphere;
  out.median_log2_ratio = weighted_median(ratios);
  for (auto& r : ratios) r.first = std::abs(r.first - out.median_log2_ratio);
  out.mismatch_stops = weighted_median(ratios);
  return out;
}

}  // namespace rsibr
