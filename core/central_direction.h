// The central direction a BRDF lobe is centred on, and so the warp its radiance maps take: one
// type for the BRDFs (Brdf::central_direction, bake/brdf.h), the map sets (MapView::warp, written as
// the rsibr.warp attribute "mirror" | "normal") and the runtime's warps (runtime/warp.h).
//   Mirror: the lobe follows the mirror direction r = 2 (n.v) n - v (glossy, conductors).
//   Normal: the lobe follows the normal n (diffuse).
#pragma once

#include <string>

namespace rsibr {

// The enumerators' order is used as an index (Mirror 0, Normal 1) by tables in runtime/warp.cpp.
enum class CentralDirection { Mirror, Normal };

// "mirror" / "normal".
const char* to_string(CentralDirection direction);
// The inverse; throws std::invalid_argument naming the accepted names for anything else.
CentralDirection central_direction_from_string(const std::string& name);

}  // namespace rsibr
