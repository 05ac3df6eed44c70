// The blend's tile path before the blend engine, frozen as bench/blend_bench.cpp's baseline (see
// previous_blend.cpp). Same definition as runtime/blend.h (colour within 5e-6 relative of it).
#pragma once

#include "runtime/blend.h"

namespace rsibr::previous {

BlendResult blend(const MapSet& maps, const ViewSet& view_set, const Vec3& view_dir, const Vec3& up,
                  const BlendOptions& options = {});

}  // namespace rsibr::previous
