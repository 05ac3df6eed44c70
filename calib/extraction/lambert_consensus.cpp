#include "calib/extraction/lambert_consensus.h"

#include "core/sphere_map.h"
#include "core/luminance.h"

#include <algorithm>
#include <cmath>

namespace rsibr {

namespace {

double lum(const cv::Vec3f& p) { return luminance(p); }

// Bilinear luminance of view `mv` at world normal n, over confident taps only; false when it does
// not see n with confidence.
bool sample_at_normal(const MapView& mv, const Vec3& n, double min_conf, double* value) {
  const Vec3 nv = mv.world_from_view.transpose() * n;
  if (!(nv.z() > 0.05)) return false;
  const Vec2 px = sphere_map::pixel_from_disc(Vec2(nv.x(), nv.y()), mv.rgb.cols, mv.rgb.rows);
  const int x0 = int(std::floor(px.x())), y0 = int(std::floor(px.y()));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= mv.rgb.cols || y0 + 1 >= mv.rgb.rows) return false;
  const double fx = px.x() - x0, fy = px.y() - y0;
  double s = 0, w = 0;
  for (int k = 0; k < 4; ++k) {
    const int x = x0 + (k & 1), y = y0 + (k >> 1);
    if (!(mv.confidence.at<float>(y, x) >= min_conf)) return false;
    const double t = ((k & 1) ? fx : 1 - fx) * ((k >> 1) ? fy : 1 - fy);
    s += t * lum(mv.rgb.at<cv::Vec3f>(y, x));
    w += t;
  }
  if (!(w > 0) || !(s > 0)) return false;
  *value = s / w;
  return true;
}

}  // namespace

std::vector<LambertConsensusView> mask_lambert_inconsistencies(std::vector<MapView>& views,
                                                               const LambertConsensusOptions& o) {
  std::vector<LambertConsensusView> out(views.size());
  std::vector<cv::Mat> masks(views.size());
  std::vector<char> in(views.size(), 1);  // still a judge
  // Rounds: every remaining view judged by the other remaining ones; the view with the largest
  // masked share above max_masked is left out (its texels would bias the medians), until none is.
  for (;;) {
    for (std::size_t v = 0; v < views.size(); ++v) {
      if (!in[v]) continue;
      const MapView& mv = views[v];
      out[v] = LambertConsensusView{};
      masks[v] = cv::Mat::zeros(mv.rgb.size(), CV_8UC1);
      std::vector<double> dev;
      for (int y = 0; y < mv.rgb.rows; ++y)
        for (int x = 0; x < mv.rgb.cols; ++x) {
          if (!(mv.confidence.at<float>(y, x) >= o.min_confidence)) continue;
          const Vec2 xy = sphere_map::disc_from_pixel(Vec2(x, y), mv.rgb.cols, mv.rgb.rows);
          if (xy.squaredNorm() >= 1) continue;
          const double own = lum(mv.rgb.at<cv::Vec3f>(y, x));
          if (!(own > 0)) continue;
          const Vec3 n = mv.world_from_view * sphere_map::g_normal(xy);
          std::vector<double> others;
          for (std::size_t k = 0; k < views.size(); ++k) {
            double val;
            if (k != v && in[k] && sample_at_normal(views[k], n, o.min_confidence, &val)) others.push_back(val);
          }
          if (int(others.size()) < o.min_others) continue;
          // The median of every view's value there, this one's included: with two others, the one
          // that differs from the other two is the outlier, whichever view it is.
          others.push_back(own);
          std::sort(others.begin(), others.end());
          const std::size_t h = others.size() / 2;
          const double med = others.size() % 2 ? others[h] : 0.5 * (others[h - 1] + others[h]);
          const double d = std::log2(own / med);
          dev.push_back(d);
          ++out[v].judged;
          if (std::abs(d) > o.max_stops) masks[v].at<unsigned char>(y, x) = 1, ++out[v].masked;
        }
      if (!dev.empty()) {
        std::nth_element(dev.begin(), dev.begin() + long(dev.size() / 2), dev.end());
        out[v].median_stops = dev[dev.size() / 2];
      }
    }
    int worst = -1;
    double worst_share = o.max_masked;
    for (std::size_t v = 0; v < views.size(); ++v) {
      if (!in[v] || out[v].judged == 0) continue;
      const double share = double(out[v].masked) / out[v].judged;
      if (share > worst_share) worst = int(v), worst_share = share;
    }
    if (worst < 0) break;
    in[std::size_t(worst)] = 0;
    out[std::size_t(worst)].left_out = true;
  }
  for (std::size_t v = 0; v < views.size(); ++v) {
    if (out[v].left_out)
      views[v].confidence.setTo(0);
    else
      views[v].confidence.setTo(0, masks[v]);
  }
  return out;
}

}  // namespace rsibr
