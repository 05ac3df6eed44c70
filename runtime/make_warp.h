// The one factory of the warp implementations (runtime/warp.h): every verb, the renderer, the viewer
// and the Python module build their warp here, by name.
#pragma once

#include "formats/map_set.h"
#include "runtime/warp.h"

#include <memory>
#include <string>

namespace rsibr {

struct WarpSettings {
  // exact | precomputed | tessellated | double-indirection
  std::string name = "precomputed";
  int rings = 16;             // tessellated: rings, with 4 x rings segments
  Vec3 axis = Vec3(0, 1, 0);  // double-indirection: the view set's rotation axis in view-frame coordinates
  int table_columns = 0;      // double-indirection: parametric table columns (0: the map width)
};

// The names make_warp accepts, for help texts and errors: "exact, precomputed, tessellated or
// double-indirection".
const char* warp_names();
bool is_warp_name(const std::string& name);

// A warp for width x height destination maps. Throws std::invalid_argument naming the accepted
// names for an unknown one, and for settings the warp refuses (rings < 1, a zero axis).
std::unique_ptr<Warp> make_warp(const WarpSettings& settings, int width, int height);

// The axis a double-indirection warp wants for a map set: world_up (world frame) in each view's
// frame, averaged; every view of a ring or turntable around world_up sees it as the same vector.
// (0, 1, 0) when the average vanishes.
Vec3 axis_in_views(const MapSet& maps, const Vec3& world_up);

}  // namespace rsibr
