#include "runtime/blend.h"

#include "core/parallel.h"
#include "runtime/disc_sampler.h"
#include "core/sphere_map.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace rsibr {

double rim_fade_weight(double rho, double rim_fade) {
  if (!(rim_fade > 0)) return 1.0;
  if (!(rho > 0)) return 0.0;  // also NaN
  const double t = std::min(rho / rim_fade, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

namespace {

// One located source, ready to sample.
struct Source : DiscMap {
  WarpKind kind = WarpKind::Mirror;
  Mat3 source_from_dest = Mat3::Identity();
  double weight = 0;  // barycentric
};

bool sample(const Source& s, const Vec2& xy, double rgb[3], double* confidence) {
  return sample_disc(s, xy, rgb, confidence);
}

}  // namespace

void check_blend_inputs(const MapSet& maps, const ViewSet& view_set) {
  if (maps.views.empty()) throw std::invalid_argument("blend: the map set is empty");
  if (view_set.views().size() != maps.views.size())
    throw std::invalid_argument("blend: the view set has " + std::to_string(view_set.views().size()) +
                                " views, the map set " + std::to_string(maps.views.size()));
  for (std::size_t i = 0; i < maps.views.size(); ++i)
    if ((view_set.views()[i] - maps.views[i].view.normalized()).norm() > 1e-6)
      throw std::invalid_argument("blend: view set and map set differ at view " + std::to_string(i));
}

void check_blend_source(const MapSet& maps, int index) {
  const MapView& v = maps.views[std::size_t(index)];
  const std::string who = "blend: view " + std::to_string(index) + ": ";
  if (v.rgb.empty() || v.rgb.type() != CV_32FC3) throw std::invalid_argument(who + "map must be a non-empty CV_32FC3 image");
  if (v.rgb.cols < 2 || v.rgb.rows < 2) throw std::invalid_argument(who + "map must be at least 2 x 2");
  if (!v.confidence.empty() && (v.confidence.type() != CV_32FC1 || v.confidence.size() != v.rgb.size()))
    throw std::invalid_argument(who + "confidence must be one float channel of the map's size");
}

BlendResult blend(const MapSet& maps, const ViewSet& view_set, const Vec3& view_dir, const Vec3& up,
                  const BlendOptions& options) {
  check_blend_inputs(maps, view_set);
  if (!view_dir.allFinite() || !(view_dir.norm() > 0)) throw std::invalid_argument("blend: view direction must be finite and non-zero");
  if ((options.width > 0) != (options.height > 0) || options.width < 0 || options.height < 0)
    throw std::invalid_argument("blend: give both width and height (> 0), or neither");
  const int W = options.width > 0 ? options.width : maps.width();
  const int H = options.height > 0 ? options.height : maps.height();
  if (W < 1 || H < 1) throw std::invalid_argument("blend: empty destination size");
  static const ExactWarp exact;
  const Warp& warp = options.warp ? *options.warp : exact;
  if (!warp.supports(W, H))
    throw std::invalid_argument(std::string("blend: the ") + warp.name() + " warp does not support " + std::to_string(W) +
                                "x" + std::to_string(H));

  BlendResult result;
  result.world_from_view = world_from_view_for(view_dir, up);
  result.located = view_set.locate(view_dir, options.barycentric);
  const ViewWeights& located = result.located;
  const Mat3& T_d = result.world_from_view;

  const int n = located.count;
  Source sources[3];
  for (int k = 0; k < n; ++k) {
    const int index = located.views[std::size_t(k)];
    check_blend_source(maps, index);
    const MapView& v = maps.views[std::size_t(index)];
    Source& s = sources[k];
    s.rgb = &v.rgb;
    s.confidence = options.use_confidence && !v.confidence.empty() ? &v.confidence : nullptr;
    s.width = v.rgb.cols;
    s.height = v.rgb.rows;
    s.kind = warp_kind_from_string(v.warp);
    s.source_from_dest = v.world_from_view.transpose() * T_d;
    s.weight = located.weights[std::size_t(k)];
  }

  result.rgb = cv::Mat::zeros(H, W, CV_32FC3);
  result.weight = cv::Mat::zeros(H, W, CV_32FC1);
  if (options.source_weights)
    for (int k = 0; k < 3; ++k) result.source_weight[std::size_t(k)] = cv::Mat::zeros(H, W, CV_32FC1);

  parallel_for_rows(H, [&](int r) {
    const auto [c0, c1] = disc_span(r, W, H);
    if (c1 <= c0) return;
    const int span = c1 - c0;
    thread_local std::vector<WarpSample> buffer;  // reused: no allocation per texel
    if (buffer.size() < std::size_t(3 * span)) buffer.resize(std::size_t(3 * span));
    for (int k = 0; k < n; ++k)
      if (sources[k].weight > 0)
        warp.warp_row(sources[k].kind, sources[k].source_from_dest, W, H, r, c0, c1, buffer.data() + k * span);

    float* out = result.rgb.ptr<float>(r);
    float* out_w = result.weight.ptr<float>(r);
    float* out_sw[3] = {nullptr, nullptr, nullptr};
    if (options.source_weights)
      for (int k = 0; k < 3; ++k) out_sw[k] = result.source_weight[std::size_t(k)].ptr<float>(r);

    for (int c = c0; c < c1; ++c) {
      double acc[3] = {0, 0, 0}, total = 0;
      for (int k = 0; k < n; ++k) {
        const Source& s = sources[k];
        if (!(s.weight > 0)) continue;
        const WarpSample& ws = buffer[std::size_t(k * span + (c - c0))];
        double a = s.weight * rim_fade_weight(ws.rim, options.rim_fade);
        if (!(a > 0)) continue;
        double L[3], conf;
        if (!sample(s, ws.disc, L, &conf)) continue;
        a *= conf;
        if (!(a > 0)) continue;
        acc[0] += a * L[0];
        acc[1] += a * L[1];
        acc[2] += a * L[2];
        total += a;
        if (out_sw[k]) out_sw[k][c] = float(a);
      }
      float* o = out + 3 * c;
      if (total > 0) {
        const double inv = 1.0 / total;
        o[0] = float(acc[0] * inv);
        o[1] = float(acc[1] * inv);
        o[2] = float(acc[2] * inv);
        out_w[c] = float(total);
        continue;
      }
      // Fallback (rare): the least-faded located source, weight 0.
      const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), W, H);
      int best = -1;
      WarpSample best_sample;
      for (int k = 0; k < n; ++k) {
        const WarpSample ws =
            warp_direction(sources[k].kind, sources[k].source_from_dest * central_direction(sources[k].kind, xy));
        if (best < 0 || ws.rim > best_sample.rim) {
          best = k;
          best_sample = ws;
        }
      }
      double L[3], conf;
      if (best >= 0 && sample(sources[best], best_sample.disc, L, &conf)) {
        o[0] = float(L[0]);
        o[1] = float(L[1]);
        o[2] = float(L[2]);
      }
      out_w[c] = 0.f;
    }
  });
  return result;
}

}  // namespace rsibr
