#include "lights/probe_sources.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rsibr {

namespace {

// Bilinear weights of direction d on the lat-long grid (pixel coordinates: integers at texel
// centres, columns 0 and W-1 on the seam).
std::vector<std::pair<long, double>> bilinear_texels(const Layout& layout, const Vec3& d) {
  const Vec2 p = layout.pixel(d);
  const int W = layout.width(), H = layout.height();
  const int x0 = std::clamp(int(std::floor(p.x())), 0, W - 2), y0 = std::clamp(int(std::floor(p.y())), 0, H - 2);
  const double fx = std::clamp(p.x() - x0, 0.0, 1.0), fy = std::clamp(p.y() - y0, 0.0, 1.0);
  return {{long(y0) * W + x0, (1 - fx) * (1 - fy)},
          {long(y0) * W + x0 + 1, fx * (1 - fy)},
          {long(y0 + 1) * W + x0, (1 - fx) * fy},
          {long(y0 + 1) * W + x0 + 1, fx * fy}};
}

// Texels of the disc with their coverage x solid angle (8 x 8 points per texel).
std::vector<std::pair<long, double>> disc_texels(const Layout& layout, const Vec3& d, double rho) {
  const int W = layout.width(), H = layout.height();
  const double lat = std::asin(std::clamp(d.y(), -1.0, 1.0)), lon = std::atan2(d.x(), d.z());
  // Row range from the latitude band (lat = pi/2 - pi y / (H-1)); column range from the longitude
  // half-width asin(sin rho / cos lat), all columns when the disc holds a pole.
  const double top = std::min(kPi / 2, lat + rho), bottom = std::max(-kPi / 2, lat - rho);
  const int r0 = std::clamp(int(std::floor((kPi / 2 - top) / kPi * (H - 1))) - 1, 0, H - 1);
  const int r1 = std::clamp(int(std::ceil((kPi / 2 - bottom) / kPi * (H - 1))) + 1, 0, H - 1);
  std::vector<int> cols;
  if (std::abs(lat) + rho >= kPi / 2 - 1e-9 || std::sin(rho) >= std::cos(lat)) {
    for (int c = 0; c < W; ++c) cols.push_back(c);
  } else {
    const double half = std::asin(std::min(1.0, std::sin(rho) / std::cos(lat)));
    // lon = pi - 2 pi x / (W-1): x = (pi - lon) (W-1) / (2 pi), wrapped over the W-1 distinct columns.
    const double xc = (kPi - lon) * (W - 1) / (2 * kPi), xh = half * (W - 1) / (2 * kPi) + 1;
    for (int k = int(std::floor(xc - xh)); k <= int(std::ceil(xc + xh)); ++k) {
      const int c = ((k % (W - 1)) + (W - 1)) % (W - 1);
      if (std::find(cols.begin(), cols.end(), c) == cols.end()) cols.push_back(c);
      if (c == 0 && std::find(cols.begin(), cols.end(), W - 1) == cols.end()) cols.push_back(W - 1);
    }
  }
  const double cos_rho = std::cos(rho);
  std::vector<std::pair<long, double>> out;
  for (int r = r0; r <= r1; ++r)
    for (int c : cols) {
      int inside = 0, total = 0;
      for (int a = 0; a < 8; ++a)
        for (int b = 0; b < 8; ++b) {
          const auto w = layout.direction(Vec2(c - 0.5 + (b + 0.5) / 8, r - 0.5 + (a + 0.5) / 8));
          if (!w) continue;
          ++total;
          inside += w->normalized().dot(d) >= cos_rho;
        }
      if (inside > 0 && total > 0)
        out.push_back({long(r) * W + c, double(inside) / total * layout.texel_solid_angle(c, r)});
    }
  return out;
}

}  // namespace

std::vector<double> add_sources_to_probe(EnvMap& probe, const std::vector<LightSource>& sources) {
  const Layout& layout = probe.layout;
  if (layout.kind() != LayoutKind::LatLong || probe.pixels.depth() != CV_32F || probe.channels() < 3)
    throw std::invalid_argument("sources: the probe must be a float lat-long map with RGB");
  const int W = layout.width(), ch = probe.channels();
  std::vector<double> footprints;
  for (const LightSource& s : sources) {
    const Vec3 d = s.direction.normalized();
    std::vector<std::pair<long, double>> weights;  // (texel, w_t)
    const Vec2 p = layout.pixel(d);
    const int c0 = std::clamp(int(std::lround(p.x())), 0, W - 1),
              r0 = std::clamp(int(std::lround(p.y())), 0, layout.height() - 1);
    if (s.radius > 0 && s.solid_angle() > 2 * layout.texel_solid_angle(c0, r0)) {
      weights = disc_texels(layout, d, s.radius);
      double sum = 0;
      for (const auto& [t, w] : weights) sum += w;
      if (sum > 0)
        for (auto& tw : weights) tw.second /= sum;
      else
        weights.clear();
    }
    if (weights.empty()) weights = bilinear_texels(layout, d);
    double footprint = 0;
    for (const auto& [t, w] : weights) {
      if (!(w > 0)) continue;
      const int r = int(t / W), c = int(t % W);
      const double omega = layout.texel_solid_angle(c, r);
      if (!(omega > 0)) continue;
      float* px = probe.pixels.ptr<float>(r) + c * ch;
      for (int k = 0; k < 3; ++k) px[k] += float(s.power[k] * w / omega);
      footprint += w * omega;
    }
    // sum_t w_t Omega_t: the solid angle over which the radiance power / footprint would give P
    // with the same weights (for a disc, its rasterised solid angle).
    footprints.push_back(footprint);
  }
  return footprints;
}

nlohmann::json light_sources_json(const std::vector<LightSource>& sources, const std::vector<double>& footprints) {
  nlohmann::json list = nlohmann::json::array();
  auto vec = [](const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); };
  const double deg = 180 / kPi;
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const LightSource& s = sources[i];
    const Vec3 d = s.direction.normalized();
    const double omega = i < footprints.size() && footprints[i] > 0 ? footprints[i] : s.solid_angle();
    list.push_back({{"direction", vec(d)},
                    {"azimuth_deg", std::atan2(d.x(), d.z()) * deg},
                    {"elevation_deg", std::asin(std::clamp(d.y(), -1.0, 1.0)) * deg},
                    {"radius_deg", s.radius * deg},
                    {"radius_fitted", s.radius_fitted},
                    {"radius_sigma_deg", s.radius_sigma * deg},
                    {"solid_angle_sr", omega},
                    {"radiance", vec(omega > 0 ? Vec3(s.power / omega) : Vec3::Zero())},
                    {"power", vec(s.power)},
                    {"power_sigma", vec(s.power_sigma)},
                    {"direction_sigma_deg", s.direction_sigma * deg},
                    {"balls", s.balls},
                    {"views", s.views},
                    {"region",
                     {{"index", s.region},
                      {"solid_angle_sr", s.region_solid_angle},
                      {"radius_deg", s.region_radius * deg},
                      {"lower_bound", vec(s.lower_bound)}}}});
  }
  return list;
}

void set_light_source_attributes(EnvMap& probe, const nlohmann::json& sources) {
  probe.attributes["lightSources"] = sources.dump();
  probe.attributes["lightSourceCount"] = std::to_string(sources.size());
}

}  // namespace rsibr
