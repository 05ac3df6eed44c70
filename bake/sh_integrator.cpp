#include "bake/sh_integrator.h"

#include "bake/reference_integrator.h"
#include "core/parallel.h"

#include "bake/lambert.h"

#include <array>
#include <cmath>
#include <vector>
#include <stdexcept>

namespace rsibr {

std::array<double, 9> ShIntegrator::basis(const Vec3& d) {
  const double x = d.x(), y = d.y(), z = d.z();
  // Normalisation constants in full precision: sqrt(1/4pi), sqrt(3/4pi), sqrt(15/4pi),
  // sqrt(5/16pi), sqrt(15/16pi) (R&H print them rounded to 6 digits).
  static const double k0 = std::sqrt(1 / (4 * kPi)), k1 = std::sqrt(3 / (4 * kPi)), k2 = std::sqrt(15 / (4 * kPi)),
                      k20 = std::sqrt(5 / (16 * kPi)), k22 = std::sqrt(15 / (16 * kPi));
  return {k0, k1 * y, k1 * z, k1 * x, k2 * x * y, k2 * y * z, k20 * (3 * z * z - 1), k2 * x * z, k22 * (x * x - y * y)};
}

ShIntegrator::ShIntegrator(const EnvMap& env) {
  // Projection with exact texel solid angles: the reference integrator's (direction, L*Omega) list.
  // Rows in parallel, each row's sums added in row order (the same bits on any threads).
  const int h = env.layout.height();
  std::vector<std::array<Vec3, 9>> rows(static_cast<std::size_t>(h));
  parallel_for_rows(h, [&](int r) {
    std::vector<ReferenceIntegrator::Texel> texels;
    ReferenceIntegrator::append_row_texels(env, r, texels);
    auto& sums = rows[std::size_t(r)];
    for (auto& c : sums) c = Vec3::Zero();
    for (const auto& t : texels) {
      const auto y = basis(t.dir);
      for (int k = 0; k < 9; ++k) sums[std::size_t(k)] += t.radiance * y[std::size_t(k)];
    }
  });
  for (auto& c : coeffs_) c = Vec3::Zero();
  for (const auto& sums : rows)
    for (int k = 0; k < 9; ++k) coeffs_[std::size_t(k)] += sums[std::size_t(k)];
}

Vec3 ShIntegrator::irradiance(const Vec3& n) const {
  static constexpr double A[9] = {kPi,     2 * kPi / 3, 2 * kPi / 3, 2 * kPi / 3, kPi / 4,
                                  kPi / 4, kPi / 4,     kPi / 4,     kPi / 4};
  const auto y = basis(n);
  Vec3 e = Vec3::Zero();
  for (int k = 0; k < 9; ++k) e += A[k] * y[std::size_t(k)] * coeffs_[std::size_t(k)];
  // The truncated series rings below zero opposite a strong, small source (a sun): clamp.
  return e.cwiseMax(0.0);
}

cv::Mat ShIntegrator::radiance_map(const Brdf& brdf, const Vec3& view, const Mat3& world_from_view, int size,
                                   const IntegratorOptions& options, const std::function<void(int)>& progress) const {
  const auto* lambert = dynamic_cast<const LambertBrdf*>(&brdf);
  if (!lambert)
    throw std::invalid_argument("sh: spherical harmonics irradiance supports only the lambert BRDF (got " +
                                brdf.spec() + ")");
  const Vec3 rho = lambert->rho();
  return integrator_detail::for_each_texel(
      size, view, world_from_view, options.texel_mask,
      [&](long, const integrator_detail::TexelFrame& t) {
        return Vec3(rho.cwiseProduct(irradiance(t.frame.normal())) / kPi);
      },
      progress);
}

}  // namespace rsibr
