// Irradiance of a distant environment, E(n) = int L_env(w) max(0, n.w) dw (RGB), by quadrature
// over texel cells with the bright texels split off:
//
//   E(n) = sum_{q bright} L(q) Omega(q) max(0, n.w_q)  +  sum_{p of R} L_R(p) Omega(p) max(0, n.w_p)
//
// Bright texels (luminance >= 10 x the solid-angle mean, at most 4096, brightest power first) are
// taken at full resolution, so a sun keeps its position; the rest R (bright texels zeroed) is
// integrated on its MIP level at most 128 texels wide (core/mip_pyramid.h: exact energy; its
// smooth remainder moves by at most half a texel). Measured against brute force over every texel:
// tests/capture/true_sphere_map_test.cpp, rig_renderer_test.cpp.
#pragma once

#include "core/env_map.h"

#include <vector>

namespace rsibr {

class IrradianceQuadrature {
 public:
  explicit IrradianceQuadrature(const EnvMap& env, int rest_width = 128, double bright_ratio = 10,
                                int max_bright = 4096);
  Vec3 operator()(const Vec3& n) const;
  // E at every texel centre of a lat-long map `width` wide (RGB, CV_32FC3), for bilinear lookups.
  EnvMap latlong_map(int width) const;
  std::size_t nodes() const { return x_.size(); }
  Vec3 node_direction(std::size_t i) const { return Vec3(x_[i], y_[i], z_[i]); }
  double node_solid_angle(std::size_t i) const { return omega_[i]; }
  Vec3 node_power(std::size_t i) const { return Vec3(r_[i], g_[i], b_[i]); }
  // Replaces the radiance seen through node i (power = radiance * its solid angle): occlusion.
  void set_node_radiance(std::size_t i, const Vec3& radiance);

 private:
  void add(const Vec3& dir, const Vec3& power, double omega);
  // Quadrature nodes as arrays (the sum vectorises): unit direction, and L * Omega per channel.
  std::vector<double> x_, y_, z_, r_, g_, b_, omega_;
};

}  // namespace rsibr
