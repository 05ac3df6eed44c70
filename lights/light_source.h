// A compact light source recovered where the probe was clipped (lights/source_recovery.h): a disc
// of uniform radiance at infinity, and the integrals the grey and glossy balls see of it.
//
// Units: power = integral of L over the disc = L * Omega (the probe's radiance unit times sr), RGB;
// directions world, unit, pointing from the origin TOWARD the source (the direction light arrives
// from, as an environment's texel direction).
//
// The grey ball's kernel: the mean over the disc (half angle rho, centre d) of the clamped cosine,
//
//   K(n) = (1 / Omega) int_cap max(0, n.w) dw,       Omega = 2 pi (1 - cos rho),
//
// so a Lambert ball of albedo a reflects (a / pi) * power * K(n). With the cap's frame (axis d, e1
// in the plane of d and n), w = cos t d + sin t (cos phi e1 + sin phi e2), n.w = A + B cos phi with
// A = cos t cos theta, B = sin t sin theta >= 0 (theta the angle from n to d), and
//
//   int_0^2pi max(0, A + B cos phi) dphi = 2 pi A                          A >= B
//                                        = 0                                A <= -B
//                                        = 2 (A acos(-A / B) + sqrt(B^2 - A^2))   otherwise,
//
// so only the integral over t in [0, rho] (weight sin t) is numerical: 16-point Gauss-Legendre.
// When the whole cap is above the horizon this is pi sin^2 rho cos theta / Omega =
// cos theta (1 + cos rho) / 2; rho -> 0 gives max(0, cos theta).
#pragma once

#include "core/vec.h"

#include <cmath>
#include <string>
#include <vector>

namespace rsibr {

struct LightSource {
  Vec3 direction = Vec3::UnitY();   // world, unit
  double radius = 0;                // the disc's angular radius (rad); 0: a point
  Vec3 power = Vec3::Zero();        // RGB, L * Omega
  Vec3 power_sigma = Vec3::Zero();  // 1-sigma of power (the larger of the fit's and the views' spread)
  double direction_sigma = 0;       // 1-sigma of the direction (rad)
  double radius_sigma = 0;          // 0 when the radius was not fitted
  bool radius_fitted = false;       // a glossy ball constrained the radius
  // Where it came from.
  int region = -1;                  // index of the clipped region (lights/clipped_regions.h)
  double region_solid_angle = 0;    // sr
  double region_radius = 0;         // rad
  Vec3 lower_bound = Vec3::Zero();  // the region's clipped values times solid angle (RGB): at least this
  std::vector<std::string> balls;   // the balls whose maps constrained it
  std::vector<std::string> views;   // the views (image names) whose maps it lit, with trusted texels

  double solid_angle() const { return 2 * kPi * (1 - std::cos(radius)); }
};

namespace light_kernels {

// The 16-point Gauss-Legendre rule on [-1, 1].
inline constexpr double kGaussX[8] = {0.0950125098376374, 0.2816035507792589, 0.4580167776572274, 0.6178762444026438,
                                      0.7554044083550030, 0.8656312023878318, 0.9445750230732326, 0.9894009349916499};
inline constexpr double kGaussW[8] = {0.1894506104550685, 0.1826034150449236, 0.1691565193950025, 0.1495959888165767,
                                      0.1246289712555339, 0.0951585116824928, 0.0622535239386479, 0.0271524594117541};

// The mean clamped cosine K of the header, for cos_theta = n.d and a radius rho >= 0. Templated so
// that Ceres can differentiate it (T = double or ceres::Jet).
template <typename T>
T mean_clamped_cosine(const T& cos_theta, const T& rho) {
  using std::acos;
  using std::cos;
  using std::sin;
  using std::sqrt;
  const T ct = cos_theta > T(1) ? T(1) : (cos_theta < T(-1) ? T(-1) : cos_theta);
  if (rho < T(1e-7)) return ct > T(0) ? ct : T(0);
  const T st = sqrt(T(1) - ct * ct + T(1e-300));
  // Entirely above or below the horizon: closed forms.
  if (acos(ct) + rho <= T(kPi / 2)) return ct * (T(1) + cos(rho)) / T(2);
  if (acos(ct) - rho >= T(kPi / 2)) return T(0);
  T sum = T(0);
  for (int i = 0; i < 16; ++i) {
    const double x = i < 8 ? -kGaussX[7 - i] : kGaussX[i - 8];
    const double wgt = i < 8 ? kGaussW[7 - i] : kGaussW[i - 8];
    const T t = rho * T(0.5 * (x + 1));
    const T a = cos(t) * ct, b = sin(t) * st;
    T g;
    if (a >= b)
      g = T(2 * kPi) * a;
    else if (a <= -b)
      g = T(0);
    else
      g = T(2) * (a * acos(-a / b) + sqrt(b * b - a * a));
    sum += T(wgt) * g * sin(t);
  }
  const T integral = sum * rho * T(0.5);
  return integral / (T(2 * kPi) * (T(1) - cos(rho)));
}

// Unit directions and equal solid-angle weights covering the cap (axis d, radius rho): rings
// equally spaced in cos t, 4 x rings azimuths each; a single point (d) when rings = 1 and rho = 0.
std::vector<Vec3> cap_points(const Vec3& d, double rho, int rings);

}  // namespace light_kernels

}  // namespace rsibr
