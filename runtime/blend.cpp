#include "runtime/blend.h"

#include "runtime/blend_engine.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace rsibr {

double rim_fade_weight(double rho, double rim_fade) {
  if (!(rim_fade > 0)) return 1.0;
  if (!(rho > 0)) return 0.0;  // also NaN
  const double t = std::min(rho / rim_fade, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

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
  if (v.rgb.empty() || v.rgb.type() != CV_32FC3)
    throw std::invalid_argument(who + "map must be a non-empty CV_32FC3 image");
  if (v.rgb.cols < 2 || v.rgb.rows < 2) throw std::invalid_argument(who + "map must be at least 2 x 2");
  if (!v.confidence.empty() && (v.confidence.type() != CV_32FC1 || v.confidence.size() != v.rgb.size()))
    throw std::invalid_argument(who + "confidence must be one float channel of the map's size");
}

BlendResult blend(const MapSet& maps, const ViewSet& view_set, const Vec3& view_dir, const Vec3& up,
                  const BlendOptions& options) {
  return BlendEngine(maps, view_set, options).map(view_dir, up, options);
}

}  // namespace rsibr
