// The light probe: chrome-ball sphere maps of several views (captured map sets from extraction, in
// one world frame) blended into one lat-long environment, each view weighted by its confidence
// channel (0 at the camera's reflection, the stand, clipped pixels; fading at the stretched rim), so
// every view's camera and rim are filled by the others.
//
// For a world direction w and a view with frame T (world_from_view): r = T^T w, texel at
// g_mirror_inv(r) (core/sphere_map.h), RGB and confidence bilinear. A chrome map holds F(cos) L(w)
// with cos = n.v = sqrt((1 + r.z) / 2) (the half angle); `fresnel`, when given, is divided out so the
// probe holds L. Texels whose summed confidence is below min_weight are 0 (no view saw them).
#pragma once

#include "bake/fresnel.h"
#include "core/env_map.h"
#include "core/map_set.h"

namespace rsibr {

struct ProbeOptions {
  int width = 256;                  // lat-long width (height = width / 2)
  const Fresnel* fresnel = nullptr; // the ball's Fresnel, divided out; none: the probe is F L
  double min_weight = 1e-3;
};

struct Probe {
  EnvMap env;               // lat-long, RGB
  cv::Mat weight;           // CV_32FC1, summed confidence per texel
  double covered_fraction = 0;  // solid-angle fraction with weight >= min_weight
};

// Throws std::invalid_argument when the set is empty or has no confidence channel (not captured).
Probe assemble_probe(const MapSet& chrome, const ProbeOptions& options = {});

}  // namespace rsibr
