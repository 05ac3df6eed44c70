// The blend's definition (runtime/blend.h, steps 1-6) evaluated the plain way, as the tests' oracle
// for the blend engine (runtime/blend_engine.h): per texel, in double, through Warp::warp_row and
// sample_disc (runtime/disc_sampler.h), with no layout, tiling or vectorisation of its own. Slow;
// for tests and measurements only.
#pragma once

#include "core/albedo_normalisation.h"
#include "core/sphere_map.h"
#include "runtime/blend.h"
#include "runtime/disc_sampler.h"
#include "runtime/warp.h"

#include <string>
#include <vector>

namespace rsibr::testing {

inline BlendResult blend_oracle(const MapSet& maps, const ViewSet& view_set, const Vec3& view_dir, const Vec3& up,
                                const BlendOptions& options = {}) {
  check_blend_inputs(maps, view_set);
  const int W = options.width > 0 ? options.width : maps.width();
  const int H = options.height > 0 ? options.height : maps.height();
  static const ExactWarp exact;
  const Warp& warp = options.warp ? *options.warp : exact;

  BlendResult result;
  result.world_from_view = world_from_view_for(view_dir, up);
  result.located = view_set.locate(view_dir, options.barycentric);
  const ViewWeights& located = result.located;
  struct Source : DiscMap {
    CentralDirection kind = CentralDirection::Mirror;
    Mat3 source_from_dest = Mat3::Identity();
    double weight = 0;
  };
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
    s.kind = v.warp;
    s.source_from_dest = v.world_from_view.transpose() * result.world_from_view;
    s.weight = located.weights[std::size_t(k)];
  }
  result.rgb = cv::Mat::zeros(H, W, CV_32FC3);
  result.weight = cv::Mat::zeros(H, W, CV_32FC1);
  for (int k = 0; k < 3; ++k) result.source_weight[std::size_t(k)] = cv::Mat::zeros(H, W, CV_32FC1);

  std::vector<WarpSample> samples;
  for (int r = 0; r < H; ++r) {
    const auto [c0, c1] = disc_span(r, W, H);
    if (c1 <= c0) continue;
    const int span = c1 - c0;
    samples.assign(std::size_t(3 * span), WarpSample{});
    for (int k = 0; k < n; ++k)
      if (sources[k].weight > 0)
        warp.warp_row(sources[k].kind, sources[k].source_from_dest, W, H, r, c0, c1, samples.data() + k * span);
    for (int c = c0; c < c1; ++c) {
      double acc[3] = {0, 0, 0}, total = 0;
      for (int k = 0; k < n; ++k) {
        const Source& s = sources[k];
        if (!(s.weight > 0)) continue;
        const WarpSample& ws = samples[std::size_t(k * span + (c - c0))];
        double a = s.weight * rim_fade_weight(ws.rim, options.rim_fade);
        if (!(a > 0)) continue;
        double L[3], conf;
        if (!sample_disc(s, ws.disc, L, &conf)) continue;
        a *= conf;
        if (!(a > 0)) continue;
        for (int j = 0; j < 3; ++j) acc[j] += a * L[j];
        total += a;
        result.source_weight[std::size_t(k)].at<float>(r, c) = float(a);
      }
      cv::Vec3f& o = result.rgb.at<cv::Vec3f>(r, c);
      if (total > 0) {
        for (int j = 0; j < 3; ++j) o[j] = float(acc[j] / total);
        result.weight.at<float>(r, c) = float(total);
        continue;
      }
      // Step 5: the least-faded located source (zero-weight ones included), weight 0.
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
      if (best >= 0 && sample_disc(sources[best], best_sample.disc, L, &conf))
        for (int j = 0; j < 3; ++j) o[j] = float(L[j]);
    }
  }
  if (!options.source_weights)
    for (auto& m : result.source_weight) m.release();
  const std::vector<float>& albedo = maps.views.front().albedo;
  if (!albedo.empty()) denormalise_by_albedo(result.rgb, albedo);
  return result;
}

}  // namespace rsibr::testing
