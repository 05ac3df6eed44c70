// Warps from the unit square [0,1)^2 to directions, with their solid-angle densities.
// Deterministic: the same u gives the same direction.
#pragma once

#include "core/vec.h"

#include <algorithm>
#include <cmath>

namespace rsibr::warp {

// Shirley-Chiu concentric map of the square onto the unit disc (area preserving up to the
// constant pi/4, continuous, no fold).
inline Vec2 square_to_concentric_disc(const Vec2& u) {
  const double a = 2.0 * u.x() - 1.0, b = 2.0 * u.y() - 1.0;
  if (a == 0.0 && b == 0.0) return Vec2(0, 0);
  double r, phi;
  if (std::abs(a) > std::abs(b)) {
    r = a;
    phi = (kPi / 4.0) * (b / a);
  } else {
    r = b;
    phi = kPi / 2.0 - (kPi / 4.0) * (a / b);
  }
  return Vec2(r * std::cos(phi), r * std::sin(phi));
}

// Cosine-weighted upper hemisphere about +z (Malley): pdf = cos(theta) / pi.
inline Vec3 square_to_cosine_hemisphere(const Vec2& u) {
  const Vec2 d = square_to_concentric_disc(u);
  const double z = std::sqrt(std::max(0.0, 1.0 - d.squaredNorm()));
  return Vec3(d.x(), d.y(), z);
}
inline double cosine_hemisphere_pdf(double cos_t) { return cos_t > 0 ? cos_t / kPi : 0.0; }

// Power-cosine lobe about +z: pdf = (e+1)/(2 pi) cos^e(theta) on the upper hemisphere.
//   CDF in cos: P(cos theta >= c) = 1 - c^(e+1)  =>  cos theta = u1^(1/(e+1)).
inline Vec3 square_to_power_cosine(const Vec2& u, double e) {
  const double c = std::pow(u.x(), 1.0 / (e + 1.0));
  const double s = std::sqrt(std::max(0.0, 1.0 - c * c));
  const double phi = 2.0 * kPi * u.y();
  return Vec3(s * std::cos(phi), s * std::sin(phi), c);
}
inline double power_cosine_pdf(double cos_t, double e) {
  return cos_t > 0 ? (e + 1.0) / (2.0 * kPi) * std::pow(cos_t, e) : 0.0;
}

// Midpoint rule on an n x n grid of the unit square: the mean of f(u). Deterministic; used to
// integrate sample weights (an integral over the hemisphere mapped onto the square by a sampler).
template <class F>
auto square_midpoint_mean(int n, F&& f) -> decltype(f(Vec2())) {
  decltype(f(Vec2())) sum = f(Vec2(0.5 / n, 0.5 / n)) * 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) sum += f(Vec2((i + 0.5) / n, (j + 0.5) / n));
  return sum / (double(n) * n);
}

// The same mean with the rows graded toward u.x = 1, where the tails of the visible-normal
// samplers lie (u.x -> 1 is the rim of the projected disc: grazing microfacets):
//   u.x = 1 - (1-t)^3,  du.x = 3 (1-t)^2 dt,  midpoint rule in t.
// Near u.x = 1 the rows are n^2/3 times finer than the uniform rule's.
template <class F>
auto square_graded_mean(int n, F&& f) -> decltype(f(Vec2())) {
  decltype(f(Vec2())) sum = f(Vec2(0.5, 0.5)) * 0.0;
  for (int i = 0; i < n; ++i) {
    const double t = (i + 0.5) / n, r = 1.0 - t;
    const double ux = 1.0 - r * r * r, w = 3.0 * r * r;
    for (int j = 0; j < n; ++j) sum += f(Vec2(ux, (j + 0.5) / n)) * w;
  }
  return sum / (double(n) * n);
}

}  // namespace rsibr::warp
