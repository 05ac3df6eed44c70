// The GGX / Trowbridge-Reitz microfacet distribution (isotropic, roughness alpha) with Smith
// masking, in the local shading frame (n = +z). Microfacet normals m are unit, m.z >= 0.
//
//   D(m)      = 1 / (pi a^2 ((m.x^2 + m.y^2)/a^2 + m.z^2)^2)          (int D(m) m.z dm = 1)
//   Lambda(w) = (sqrt(1 + a^2 tan^2 theta) - 1) / 2
//             = x / (2 (sqrt(1 + x) + 1)),  x = a^2 (w.x^2 + w.y^2) / w.z^2   (no cancellation)
//   G1(w)     = 1 / (1 + Lambda(w))
//   G2(o, i)  = 1 / (1 + Lambda(o) + Lambda(i))     height-correlated Smith (Heitz 2014)
//   D_o(m)    = G1(o) max(0, o.m) D(m) / o.z        visible normals, int D_o(m) dm = 1
// Directions on or below the horizon have G1 = G2 = 0.
#pragma once

#include "core/vec.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rsibr {

struct GgxDistribution {
  double alpha;

  double D(const Vec3& m) const {
    if (!(m.z() > 0)) return 0.0;
    const double a2 = alpha * alpha;
    const double s = (m.x() * m.x() + m.y() * m.y()) / a2 + m.z() * m.z();
    return 1.0 / (kPi * a2 * s * s);
  }

  double lambda(const Vec3& w) const {
    if (!(w.z() > 0)) return std::numeric_limits<double>::infinity();
    const double x = alpha * alpha * (w.x() * w.x() + w.y() * w.y()) / (w.z() * w.z());
    return x / (2.0 * (std::sqrt(1.0 + x) + 1.0));
  }

  double G1(const Vec3& w) const { return w.z() > 0 ? 1.0 / (1.0 + lambda(w)) : 0.0; }

  double G2(const Vec3& wo, const Vec3& wi) const {
    if (!(wo.z() > 0 && wi.z() > 0)) return 0.0;
    return 1.0 / (1.0 + lambda(wo) + lambda(wi));
  }

  // Density of visible normals D_o(m) (solid angle of m).
  double pdf_visible(const Vec3& wo, const Vec3& m) const {
    const double om = wo.dot(m);
    if (!(wo.z() > 0 && om > 0)) return 0.0;
    return G1(wo) * om * D(m) / wo.z();
  }

  // Samples m from D_o (Heitz 2018, "Sampling the GGX distribution of visible normals"):
  // stretch wo to the alpha = 1 configuration, sample the projected hemisphere seen from it
  // (a disc, its far half squashed by (1 + Vh.z)/2), lift to the hemisphere, unstretch.
  // Requires wo.z > 0; u in [0,1)^2. The result is unit with m.z >= 0 and wo.m >= 0.
  Vec3 sample_visible(const Vec3& wo, const Vec2& u) const {
    const Vec3 vh = Vec3(alpha * wo.x(), alpha * wo.y(), wo.z()).normalized();
    const double lensq = vh.x() * vh.x() + vh.y() * vh.y();
    const Vec3 t1 = lensq > 0 ? Vec3(Vec3(-vh.y(), vh.x(), 0) / std::sqrt(lensq)) : Vec3(1, 0, 0);
    const Vec3 t2 = vh.cross(t1);
    const double r = std::sqrt(u.x()), phi = 2.0 * kPi * u.y();
    const double p1 = r * std::cos(phi);
    double p2 = r * std::sin(phi);
    const double s = 0.5 * (1.0 + vh.z());
    p2 = (1.0 - s) * std::sqrt(std::max(0.0, 1.0 - p1 * p1)) + s * p2;
    const Vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    return Vec3(alpha * nh.x(), alpha * nh.y(), std::max(0.0, nh.z())).normalized();
  }
};

}  // namespace rsibr
