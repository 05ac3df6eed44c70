#include "capture/irradiance.h"

#include "core/mip_pyramid.h"
#include "core/parallel.h"
#include "core/luminance.h"

#include <algorithm>
#include <numeric>

namespace rsibr {
namespace {}  // namespace

IrradianceQuadrature::IrradianceQuadrature(const EnvMap& env, int rest_width, double bright_ratio, int max_bright) {
  const Layout& lay = env.layout;
  const int ch = env.channels();
  // Mean luminance over solid angle, and the candidates above ratio x mean.
  double sum = 0, omega_sum = 0;
  struct Candidate {
    int c, r;
    double power;
  };
  std::vector<Candidate> bright;
  for (int r = 0; r < lay.height(); ++r)
    for (int c = 0; c < lay.width(); ++c) {
      const double om = lay.texel_solid_angle(c, r);
      sum += om * luminance(env.pixels.ptr<float>(r) + c * ch);
      omega_sum += om;
    }
  const double mean = omega_sum > 0 ? sum / omega_sum : 0;
  for (int r = 0; r < lay.height(); ++r)
    for (int c = 0; c < lay.width(); ++c) {
      const double y = luminance(env.pixels.ptr<float>(r) + c * ch);
      if (mean > 0 && y >= bright_ratio * mean && lay.texel_direction(c, r))
        bright.push_back({c, r, y * lay.texel_solid_angle(c, r)});
    }
  std::stable_sort(bright.begin(), bright.end(),
                   [](const Candidate& a, const Candidate& b) { return a.power > b.power; });
  if (int(bright.size()) > max_bright) bright.resize(std::size_t(max_bright));
  EnvMap rest = env;
  rest.pixels = env.pixels.clone();
  for (const Candidate& b : bright) {
    float* p = rest.pixels.ptr<float>(b.r) + b.c * ch;
    add(*lay.texel_direction(b.c, b.r), lay.texel_solid_angle(b.c, b.r) * Vec3(p[0], p[1], p[2]),
        lay.texel_solid_angle(b.c, b.r));
    for (int k = 0; k < ch; ++k) p[k] = 0;
  }
  const MipPyramid pyramid(rest);
  int level = 0;
  while (level + 1 < pyramid.levels() && pyramid.level(level).layout.width() > rest_width) ++level;
  const EnvMap& src = pyramid.level(level);
  for (int r = 0; r < src.layout.height(); ++r)
    for (int c = 0; c < src.layout.width(); ++c) {
      const auto d = src.layout.texel_direction(c, r);
      const float* p = src.pixels.ptr<float>(r) + c * src.channels();
      const Vec3 L(p[0], p[1], p[2]);
      if (!d || L.isZero()) continue;
      add(*d, src.layout.texel_solid_angle(c, r) * L, src.layout.texel_solid_angle(c, r));
    }
}

void IrradianceQuadrature::add(const Vec3& dir, const Vec3& power, double omega) {
  omega_.push_back(omega);
  x_.push_back(dir.x());
  y_.push_back(dir.y());
  z_.push_back(dir.z());
  r_.push_back(power.x());
  g_.push_back(power.y());
  b_.push_back(power.z());
}

void IrradianceQuadrature::set_node_radiance(std::size_t i, const Vec3& radiance) {
  r_[i] = omega_[i] * radiance.x();
  g_[i] = omega_[i] * radiance.y();
  b_[i] = omega_[i] * radiance.z();
}

Vec3 IrradianceQuadrature::operator()(const Vec3& n) const {
  const double nx = n.x(), ny = n.y(), nz = n.z();
  double er = 0, eg = 0, eb = 0;
  const std::size_t count = x_.size();
  for (std::size_t i = 0; i < count; ++i) {
    const double cosine = std::max(0.0, nx * x_[i] + ny * y_[i] + nz * z_[i]);
    er += cosine * r_[i];
    eg += cosine * g_[i];
    eb += cosine * b_[i];
  }
  return Vec3(er, eg, eb);
}

EnvMap IrradianceQuadrature::latlong_map(int width) const {
  EnvMap out = EnvMap::zeros(Layout::with_size(LayoutKind::LatLong, width), 3);
  parallel_for_rows(out.layout.height(), [&](int r) {
    for (int c = 0; c < out.layout.width(); ++c) {
      const Vec3 e = (*this)(*out.layout.texel_direction(c, r));
      float* px = out.pixels.ptr<float>(r) + 3 * c;
      for (int k = 0; k < 3; ++k) px[k] = float(e[k]);
    }
  });
  return out;
}

}  // namespace rsibr
