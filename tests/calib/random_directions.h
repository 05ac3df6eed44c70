// Random unit directions and small angular perturbations for the orientation tests (seeded).
#pragma once

#include "core/vec.h"

#include <random>

namespace rsibr::testing {

// Uniform on the unit sphere.
inline Vec3 random_direction(std::mt19937_64& rng) {
  std::normal_distribution<double> g(0, 1);
  return Vec3(g(rng), g(rng), g(rng)).normalized();
}

// d turned by a tangent perturbation of std dev sigma (radians) per axis.
inline Vec3 perturb(const Vec3& d, double sigma, std::mt19937_64& rng) {
  std::normal_distribution<double> g(0, sigma);
  const Vec3 t1 = d.unitOrthogonal(), t2 = d.cross(t1);
  return (d + g(rng) * t1 + g(rng) * t2).normalized();
}

}  // namespace rsibr::testing
