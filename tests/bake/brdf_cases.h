// The BRDF configurations every property test runs over, and shared direction helpers.
#pragma once

#include "bake/blinn_phong.h"
#include "bake/brdf.h"
#include "bake/clear_coat.h"
#include "bake/fresnel.h"
#include "bake/ggx.h"
#include "bake/lambert.h"
#include "bake/phong.h"

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace rsibr::test {

struct BrdfCase {
  std::string name;
  std::shared_ptr<const Brdf> brdf;
};

inline std::shared_ptr<const Fresnel> gold() {
  return std::make_shared<ConductorFresnel>(Vec3(0.143, 0.374, 1.442), Vec3(3.983, 2.385, 1.603));
}

inline std::shared_ptr<const Brdf> ggx(double alpha, std::shared_ptr<const Fresnel> f = gold()) {
  return std::make_shared<GgxBrdf>(alpha, std::move(f));
}

inline std::shared_ptr<const Brdf> car_paint(double coat_alpha = 0.05, double coverage = 0.3, double flake_alpha = 0.3,
                                             Vec3 base = Vec3(0.6, 0.08, 0.05),
                                             std::shared_ptr<const Fresnel> flake_fresnel = nullptr) {
  ClearCoatParams p;
  p.coat_ior = 1.5;
  p.coat_roughness = coat_alpha;
  p.flake_coverage = coverage;
  p.flake_roughness = flake_alpha;
  p.flake_fresnel = flake_fresnel ? std::move(flake_fresnel)
                                  : std::make_shared<ConductorFresnel>(Vec3(1.66, 0.88, 0.52), Vec3(9.2, 6.3, 4.8));
  p.base_albedo = base;
  return std::make_shared<ClearCoatBrdf>(std::move(p));
}

// Every sampler, at the lobe widths the chi-square and pdf tests must cover.
inline std::vector<BrdfCase> sampler_cases() {
  return {
      {"lambert", std::make_shared<LambertBrdf>(Vec3(0.5, 0.6, 0.7))},
      {"phong_e1", std::make_shared<PhongBrdf>(Vec3(0.9, 0.8, 0.7), 1.0)},
      {"phong_e30", std::make_shared<PhongBrdf>(Vec3(0.9, 0.8, 0.7), 30.0)},
      {"phong_e1000", std::make_shared<PhongBrdf>(Vec3(0.9, 0.8, 0.7), 1000.0)},
      {"blinn_e1", std::make_shared<BlinnPhongBrdf>(Vec3(0.9, 0.8, 0.7), 1.0)},
      {"blinn_e30", std::make_shared<BlinnPhongBrdf>(Vec3(0.9, 0.8, 0.7), 30.0)},
      {"blinn_e1000", std::make_shared<BlinnPhongBrdf>(Vec3(0.9, 0.8, 0.7), 1000.0)},
      {"ggx_a0.05", ggx(0.05)},
      {"ggx_a0.1", ggx(0.1)},
      {"ggx_a0.3", ggx(0.3)},
      {"ggx_a0.6", ggx(0.6)},
      {"ggx_a1", ggx(1.0)},
      {"clearcoat", car_paint()},
      {"clearcoat_rough",
       car_paint(0.4, 0.7, 0.08, Vec3(0.9, 0.9, 0.9), std::make_shared<SchlickFresnel>(Vec3(0.95, 0.9, 0.8)))},
  };
}

// Unit direction with the given cos theta and azimuth.
inline Vec3 dir(double cos_t, double phi = 0.3) {
  const double s = std::sqrt(std::max(0.0, 1.0 - cos_t * cos_t));
  return Vec3(s * std::cos(phi), s * std::sin(phi), cos_t);
}

// The viewing directions of the sampler tests: normal, 45 degrees, 78 degrees, grazing.
inline std::vector<Vec3> test_wos() { return {dir(1.0), dir(0.7, 0.3), dir(0.2, 2.0), dir(0.01, -1.2)}; }

inline Vec3 random_upper(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  for (;;) {
    Vec3 v(g(rng), g(rng), g(rng));
    if (v.norm() > 1e-6) {
      v.normalize();
      v.z() = std::abs(v.z());
      if (v.z() > 0) return v;
    }
  }
}

// The peaks to resolve when integrating a lobe of wo: normal, mirror direction, wo itself.
inline std::vector<Vec3> lobe_peaks(const Vec3& wo) { return {Vec3(0, 0, 1), Vec3(-wo.x(), -wo.y(), wo.z()), wo, -wo}; }

}  // namespace rsibr::test
