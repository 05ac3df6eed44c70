// Map sets with a known answer at every view, built texel by texel from the invariant
// (docs/conventions.md): texel p of the map for view v (frame T = world_from_view_for(v)) holds the
// radiance leaving a surface with normal T g_normal(p) toward a viewer along v.
#pragma once

#include "formats/map_set.h"
#include "core/sphere_map.h"
#include "core/view_set.h"
#include "runtime/blend.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

namespace rsibr::testing {

// Radiance of texel xy (disc coordinates) of the map whose frame is T (view = T's third column).
using TexelFunction = std::function<Vec3(const Mat3& T, const Vec2& xy)>;

// The analytic map for one frame: texels whose centre lies outside the disc are 0.
inline cv::Mat analytic_map(const TexelFunction& f, const Mat3& T, int width, int height) {
  cv::Mat m = cv::Mat::zeros(height, width, CV_32FC3);
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) {
      const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), width, height);
      if (xy.squaredNorm() > 1.0) continue;
      const Vec3 L = f(T, xy);
      m.at<cv::Vec3f>(r, c) = cv::Vec3f(float(L.x()), float(L.y()), float(L.z()));
    }
  return m;
}

inline MapSet analytic_map_set(const ViewSet& views, int width, int height, const std::string& warp,
                               const TexelFunction& f) {
  MapSet set;
  for (const Vec3& v : views.views()) {
    MapView mv;
    mv.view = v;
    mv.world_from_view = world_from_view_for(v);
    mv.warp = central_direction_from_string(warp);
    mv.rgb = analytic_map(f, mv.world_from_view, width, height);
    set.views.push_back(std::move(mv));
  }
  return set;
}

// A smooth environment (every direction its own colour, plus some curvature).
inline Vec3 environment(const Vec3& w) {
  return Vec3(0.5 + 0.5 * w.x(), 0.5 + 0.5 * w.y() * w.y() + 0.2 * w.z(), 0.6 + 0.3 * std::sin(2.0 * w.z() + w.x()));
}
// A smooth, Lambert-like function of the world normal (a low-order irradiance).
inline Vec3 irradiance(const Vec3& n) {
  return Vec3(0.6 + 0.3 * n.x() + 0.1 * n.y() * n.z(), 0.5 + 0.4 * n.y(), 0.4 + 0.2 * n.z() + 0.2 * n.x() * n.x());
}
// Schlick's Fresnel factor for cos(theta) = n . v.
inline double fresnel(double cos_theta) {
  const double m = 1.0 - std::clamp(cos_theta, 0.0, 1.0);
  return 0.04 + 0.96 * m * m * m * m * m;
}

// A perfect mirror without Fresnel: view independent in reflection space.
inline Vec3 mirror_texel(const Mat3& T, const Vec2& xy) { return environment(T * sphere_map::g_mirror(xy)); }
// Lambert-like: view independent in normal space.
inline Vec3 lambert_texel(const Mat3& T, const Vec2& xy) { return irradiance(T * sphere_map::g_normal(xy)); }
// A mirror with Fresnel: depends on the view through n . v = g_normal(xy).z.
inline Vec3 fresnel_mirror_texel(const Mat3& T, const Vec2& xy) {
  return fresnel(sphere_map::g_normal(xy).z()) * environment(T * sphere_map::g_mirror(xy));
}

struct MapError {
  double max_abs = 0;
  double rms = 0;
  int texels = 0;
};

// Error of a blended map against the analytic map for the same frame, over destination texels inside
// the disc whose radius is <= max_radius (the rim of a sphere map is where it is least reliable).
inline MapError map_error(const BlendResult& b, const TexelFunction& f, double max_radius = 1.0) {
  const cv::Mat truth = analytic_map(f, b.world_from_view, b.rgb.cols, b.rgb.rows);
  MapError e;
  double sum = 0;
  for (int r = 0; r < b.rgb.rows; ++r)
    for (int c = 0; c < b.rgb.cols; ++c) {
      const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), b.rgb.cols, b.rgb.rows);
      if (xy.norm() > max_radius || xy.squaredNorm() > 1.0) continue;
      const cv::Vec3f o = b.rgb.at<cv::Vec3f>(r, c), t = truth.at<cv::Vec3f>(r, c);
      for (int k = 0; k < 3; ++k) {
        const double d = double(o[k]) - double(t[k]);
        e.max_abs = std::max(e.max_abs, std::abs(d));
        sum += d * d;
      }
      ++e.texels;
    }
  e.rms = e.texels ? std::sqrt(sum / (3.0 * e.texels)) : 0.0;
  return e;
}

inline std::vector<Vec3> random_directions(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  std::vector<Vec3> out;
  while (int(out.size()) < n) {
    const Vec3 v(g(rng), g(rng), g(rng));
    if (v.norm() > 1e-3) out.push_back(v.normalized());
  }
  return out;
}

}  // namespace rsibr::testing
