#include "calib/probe.h"

#include "core/parallel.h"
#include "core/sphere_map.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rsibr {

Probe assemble_probe(const MapSet& set, const ProbeOptions& options) {
  if (set.views.empty()) throw std::invalid_argument("probe: no views");
  for (std::size_t v = 0; v < set.views.size(); ++v)
    if (set.views[v].confidence.empty() || set.views[v].rgb.type() != CV_32FC3)
      throw std::invalid_argument("probe: view." + std::to_string(v) + " has no confidence channel (not a captured map)");
  if (options.width < 4 || options.width % 2) throw std::invalid_argument("probe: width must be even and >= 4");
  const Layout layout(LayoutKind::LatLong, options.width, options.width / 2);
  Probe probe;
  probe.env = EnvMap::zeros(layout, 3);
  probe.env.attributes["source"] = "probe";
  probe.weight = cv::Mat(layout.height(), layout.width(), CV_32FC1, cv::Scalar(0));
  std::vector<double> row_area(layout.height(), 0.0), row_covered(layout.height(), 0.0);
  parallel_for_rows(layout.height(), [&](int row) {
    for (int col = 0; col < layout.width(); ++col) {
      const auto w = layout.texel_direction(col, row);
      if (!w) continue;
      const double area = std::sqrt(std::max(0.0, 1.0 - w->y() * w->y()));  // cos(latitude)
      row_area[row] += area;
      Vec3 sum = Vec3::Zero();
      double wsum = 0;
      for (const MapView& mv : set.views) {
        const Vec3 r = mv.world_from_view.transpose() * *w;
        const Vec2 px = sphere_map::pixel_from_disc(sphere_map::g_mirror_inv(r), mv.rgb.cols, mv.rgb.rows);
        const int x0 = static_cast<int>(std::floor(px.x())), y0 = static_cast<int>(std::floor(px.y()));
        if (x0 < 0 || y0 < 0 || x0 + 1 >= mv.rgb.cols || y0 + 1 >= mv.rgb.rows) continue;
        const double fx = px.x() - x0, fy = px.y() - y0;
        const double tw[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
        const int tx[4] = {x0, x0 + 1, x0, x0 + 1}, ty[4] = {y0, y0, y0 + 1, y0 + 1};
        Vec3 c = Vec3::Zero();
        double conf = 0, cw = 0;
        for (int k = 0; k < 4; ++k) {
          const float cf = mv.confidence.at<float>(ty[k], tx[k]);
          // A tap without confidence gives nothing; the rest are renormalised (bilinear within the trusted texels).
          if (!(cf > 0)) continue;
          const cv::Vec3f p = mv.rgb.at<cv::Vec3f>(ty[k], tx[k]);
          c += tw[k] * Vec3(p[0], p[1], p[2]);
          conf += tw[k] * cf;
          cw += tw[k];
        }
        if (!(cw > 0) || !(conf > 0)) continue;
        c /= cw;
        if (options.fresnel) {
          const Vec3 f = options.fresnel->eval(std::sqrt(std::clamp(0.5 * (1 + r.normalized().z()), 0.0, 1.0)));
          c = c.cwiseQuotient(f.cwiseMax(Vec3::Constant(1e-6)));
        }
        sum += conf * c;
        wsum += conf;
      }
      if (wsum < options.min_weight) continue;
      const Vec3 l = sum / wsum;
      probe.env.pixels.at<cv::Vec3f>(row, col) = cv::Vec3f(float(l.x()), float(l.y()), float(l.z()));
      probe.weight.at<float>(row, col) = static_cast<float>(wsum);
      row_covered[row] += area;
    }
  });
  double a = 0, c = 0;
  for (int r = 0; r < layout.height(); ++r) a += row_area[r], c += row_covered[r];
  probe.covered_fraction = a > 0 ? c / a : 0;
  return probe;
}

}  // namespace rsibr
