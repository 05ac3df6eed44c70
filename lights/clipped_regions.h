// The regions of a light probe that no chrome view saw unclipped (calib/probe/probe.h: Probe::clipped,
// texels where every view that saw the direction had it clipped in every bracket): connected
// components of those texels on the lat-long sphere, each a candidate light source.
//
// Connectivity: 8 neighbours on the lat-long grid, closed across the seam (columns 0 and W-1 hold
// the same directions) and at the poles (every texel of row 0, and of row H-1, is one direction).
// Components whose centroids lie within `merge_deg` of each other are merged (greedily, the largest
// lower bound first): a bright sky clipped in scattered pixels around a sun, or two lamps closer
// than a grey ball can tell apart, are one source. (Two sources delta apart light a Lambert ball as
// one at their centroid with cos(delta / 2) of their power, away from the terminator: 3.4% at 30
// degrees, about the error of the probe's known part.) Per region: the solid-angle-weighted centroid of
// its texel centres, its solid angle, its radius (the largest angle from the centroid to a member's
// centre, plus half a texel's diagonal) and the clipped values' integral (a lower bound of its
// power). Regions are sorted by that lower bound, largest first (ties by the first texel).
#pragma once

#include "calib/probe/probe.h"

#include <vector>

namespace rsibr {

struct ClippedRegion {
  std::vector<long> texels;         // r * width + c of the probe
  Vec3 direction = Vec3::UnitY();   // world, unit
  double solid_angle = 0;           // sr
  double radius = 0;                // rad
  Vec3 lower_bound = Vec3::Zero();  // sum of Probe::lower_bound * Omega over the texels (RGB)
  double weight = 0;                // sum of Probe::clipped (how strongly the views saw it)
};

// `probe.clipped` and `probe.lower_bound` as assemble_probe fills them.
std::vector<ClippedRegion> find_clipped_regions(const Probe& probe, double merge_deg = 30);

}  // namespace rsibr
