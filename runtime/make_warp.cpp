#include "runtime/make_warp.h"

#include "runtime/double_indirection_warp.h"
#include "runtime/tessellated_warp.h"

#include <algorithm>
#include <stdexcept>

namespace rsibr {

const char* warp_names() { return "exact, precomputed, tessellated or double-indirection"; }

bool is_warp_name(const std::string& name) {
  return name == "exact" || name == "precomputed" || name == "tessellated" || name == "double-indirection";
}

std::unique_ptr<Warp> make_warp(const WarpSettings& s, int width, int height) {
  if (s.name == "exact") return std::make_unique<ExactWarp>();
  if (s.name == "precomputed") return std::make_unique<PrecomputedWarp>(width, height);
  if (s.name == "tessellated") {
    TessellationOptions t;
    t.rings = s.rings;
    t.segments = 4 * s.rings;
    return std::make_unique<TessellatedWarp>(width, height, t);
  }
  if (s.name == "double-indirection") {
    DoubleIndirectionOptions d;
    d.axis = s.axis;
    if (s.table_columns > 0) {
      d.longitudes = s.table_columns;
      d.latitudes = std::max(3, s.table_columns / 2 + 1);
    }
    return std::make_unique<DoubleIndirectionWarp>(width, height, d);
  }
  throw std::invalid_argument("warp must be " + std::string(warp_names()) + ", not '" + s.name + "'");
}

Vec3 axis_in_views(const MapSet& maps, const Vec3& world_up) {
  Vec3 sum = Vec3::Zero();
  for (const MapView& v : maps.views) sum += v.world_from_view.transpose() * world_up.normalized();
  return sum.allFinite() && sum.norm() > 1e-9 ? Vec3(sum.normalized()) : Vec3(0, 1, 0);
}

}  // namespace rsibr
