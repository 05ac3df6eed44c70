#include "plan/warp_plan.h"

#include "runtime/blend_engine.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace rsibr {
namespace {

// The fastest of three timed maps, after one untimed map that builds the warp's tables.
double time_map(const BlendEngine& engine, const Vec3& view, const Vec3& up, const MapRequest& request,
                BlendResult* first) {
  *first = engine.map(view, up, request);
  double best = 1e300;
  for (int i = 0; i < 3; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    engine.map(view, up, request);
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

double error_against(const BlendResult& b, const BlendResult& exact) {
  double num = 0, den = 0;
  for (int r = 0; r < exact.rgb.rows; ++r) {
    const cv::Vec3f* e = exact.rgb.ptr<cv::Vec3f>(r);
    const cv::Vec3f* x = b.rgb.ptr<cv::Vec3f>(r);
    const float* w = exact.weight.ptr<float>(r);
    for (int c = 0; c < exact.rgb.cols; ++c) {
      if (!(w[c] > 0)) continue;
      const cv::Vec3f d = x[c] - e[c];
      num += double(d.dot(d));
      den += double(e[c].dot(e[c]));
    }
  }
  return den > 0 ? std::sqrt(num / den) : (num > 0 ? INFINITY : 0.0);
}

}  // namespace

std::vector<WarpSettings> default_warp_candidates(const Vec3& axis) {
  std::vector<WarpSettings> w;
  w.push_back({"precomputed", 16, axis, 0});
  for (int rings : {8, 16, 32}) w.push_back({"tessellated", rings, axis, 0});
  w.push_back({"double-indirection", 16, axis, 0});
  return w;
}

WarpPlan plan_warp(const MapSet& set, const ViewSet& views, const Vec3& view, const Vec3& up, int width, int height,
                   double max_error, const std::vector<WarpSettings>& candidates, const BlendRule& rule) {
  if (!(max_error > 0 && max_error < 1))
    throw std::invalid_argument("plan: the error budget must lie in (0, 1), not " + std::to_string(max_error));
  const BlendEngine engine(set, views, rule);
  WarpPlan plan;
  plan.max_error = max_error;
  MapRequest request;
  request.width = width;
  request.height = height;
  const std::unique_ptr<Warp> exact_warp = make_warp({"exact", 16, Vec3(0, 1, 0), 0}, width, height);
  request.warp = exact_warp.get();
  BlendResult exact;
  WarpMeasure e;
  e.warp.name = "exact";
  e.seconds = time_map(engine, view, up, request, &exact);
  e.meets = true;
  plan.measured.push_back(e);
  plan.chosen = e;
  for (const WarpSettings& s : candidates) {
    const std::unique_ptr<Warp> warp = make_warp(s, width, height);
    request.warp = warp.get();
    BlendResult b;
    WarpMeasure m;
    m.warp = s;
    m.seconds = time_map(engine, view, up, request, &b);
    m.error = error_against(b, exact);
    m.meets = m.error <= max_error;
    plan.measured.push_back(m);
    if (m.meets && m.seconds < plan.chosen.seconds) plan.chosen = m;
  }
  return plan;
}

nlohmann::json WarpPlan::to_json() const {
  auto one = [](const WarpMeasure& m) {
    nlohmann::json j = {{"warp", m.warp.name}, {"error", m.error}, {"seconds", m.seconds}, {"meets", m.meets}};
    if (m.warp.name == "tessellated") j["rings"] = m.warp.rings;
    return j;
  };
  nlohmann::json j;
  j["max_error"] = max_error;
  j["chosen"] = one(chosen);
  j["measured"] = nlohmann::json::array();
  for (const WarpMeasure& m : measured) j["measured"].push_back(one(m));
  return j;
}

}  // namespace rsibr
