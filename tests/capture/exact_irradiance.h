// Irradiance E(n) = integral of L(w) max(0, n.w) dw by brute force over every texel of the
// environment (exact texel solid angles, no MIP level, no irradiance map): the grey ball's truth.
#pragma once

#include "core/env_map.h"
#include "core/vec.h"

namespace rsibr::testing {

inline Vec3 exact_irradiance(const EnvMap& env, const Vec3& n) {
  Vec3 e = Vec3::Zero();
  for (int r = 0; r < env.layout.height(); ++r)
    for (int c = 0; c < env.layout.width(); ++c) {
      const Vec3 w = *env.layout.texel_direction(c, r);
      const double cosine = n.dot(w);
      if (cosine <= 0) continue;
      const float* px = env.pixels.ptr<float>(r) + 3 * c;
      e += cosine * env.layout.texel_solid_angle(c, r) * Vec3(px[0], px[1], px[2]);
    }
  return e;
}

}  // namespace rsibr::testing
