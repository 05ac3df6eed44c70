#include "core/cell_centred_latlong.h"

#include "core/parallel.h"

#include <cmath>

namespace rsibr {

Vec3 cell_centred_latlong_direction(double i, double j, int width, int height) {
  const double lon = kPi * (1.0 - 2.0 * (i + 0.5) / width);
  const double lat = 0.5 * kPi - kPi * (j + 0.5) / height;
  // Longitude 0 at +Z, +pi/2 at +X; latitude +pi/2 at +Y (ImfEnvmap's frame).
  return Vec3(std::cos(lat) * std::sin(lon), std::sin(lat), std::cos(lat) * std::cos(lon));
}

EnvMap to_cell_centred_latlong(const EnvMap& env, int width, int height) {
  EnvMap out = EnvMap::zeros(Layout(LayoutKind::LatLong, width, height), env.channels());
  out.attributes = env.attributes;
  const int channels = env.channels();
  parallel_for_rows(height, [&](int j) {
    float* row = out.pixels.ptr<float>(j);
    for (int i = 0; i < width; ++i)
      sample_bilinear(env, cell_centred_latlong_direction(i, j, width, height), row + i * channels);
  });
  return out;
}

}  // namespace rsibr
