// The radiance of a map set for one (viewer direction, normal) pair: the blend of runtime/blend.h
// evaluated for a single direction instead of a whole destination map. The renderer's exact
// per-pixel mode uses it; blend() is its tabulation over one destination map.
//
// Invariant (seeds/README.md): texel p of the map for view v_i (frame T_i = world_from_view) holds the
// radiance leaving a surface with normal T_i g_normal(p) toward a viewer at infinity along v_i.
// For a viewer direction v (world, unit, from the surface toward the viewer) and a normal n (world,
// unit):
//   0. n is clamped to v's hemisphere: when n.v < 0, n <- (n - (n.v) v)/|n - (n.v) v|, the nearest
//      normal with n.v = 0 (the rim of v's sphere map; the paper-mode lookup takes the nearest rim
//      point too). n = -v exactly takes -world_from_view_for(v).col(1), the rim point (0,-1).
//   1. (w_0, w_1, w_2) = ViewSet::locate(v) with BlendOptions::barycentric (outside a non-surrounding
//      set: the weights of the nearest covered point, as blend()).
//   2. The central direction: mirror-warped sources use r = 2(n.v)n - v, normal-warped ones n. For
//      source i: WarpSample s_i = warp_direction(kind_i, T_i^T dir) (runtime/warp.h).
//   3. a_i = w_i * rim_fade_weight(rim_i, rim_fade) * c_i, with c_i the bilinear confidence when the
//      map has one and BlendOptions::use_confidence, else 1; sources with w_i = 0 are skipped.
//   4. L = sum_i a_i L_i / sum_i a_i, L_i sampled by sample_disc (runtime/disc_sampler.h) at s_i's
//      disc point, weight = sum_i a_i.
//   5. sum_i a_i = 0: blend()'s fallback, the least-faded located source (largest rim, ties to the
//      first, zero-weight located views included) at its clamped disc point, weight 0.
// With v = a destination view d and n = T_d g_normal(p) for a destination texel p inside the disc this
// is exactly blend()'s value of texel p (tested to float precision). Finite for finite maps and any
// finite non-zero v, n.
#pragma once

#include "core/map_set.h"
#include "core/view_set.h"
#include "runtime/blend.h"
#include "runtime/disc_sampler.h"
#include "runtime/warp.h"

#include <array>
#include <vector>

namespace rsibr {

class DirectionLookup {
 public:
  // Checks like blend() (std::invalid_argument: empty set, view_set not the set's, bad maps, unknown
  // warp names), for every view up front. Keeps references: maps and view_set must outlive it.
  // BlendOptions' width, height, warp and source_weights are not used.
  DirectionLookup(const MapSet& maps, const ViewSet& view_set, const BlendOptions& options = {});

  // ViewSet::locate(v, options.barycentric), the same result. `hint` (per caller, start at -1) holds
  // the last triangle found: when v lies strictly inside it (more than 1e-9 rad from every edge, so no
  // other triangle can contain v), the search over the set is skipped.
  ViewWeights locate(const Vec3& v, int* hint = nullptr) const;

  // Radiance (RGB, the maps' units) for unit v and unit n, both world. weight (optional) gets
  // sum_i a_i in [0, 1].
  Vec3 radiance(const Vec3& v, const Vec3& n, double* weight = nullptr) const {
    return radiance(locate(v), v, n, weight);
  }
  // The same with located = locate(v) done by the caller.
  Vec3 radiance(const ViewWeights& located, const Vec3& v, const Vec3& n, double* weight = nullptr) const;

  const MapSet& maps() const { return maps_; }
  const ViewSet& view_set() const { return view_set_; }

 private:
  struct Source : DiscMap {
    WarpKind kind = WarpKind::Mirror;
    Mat3 view_from_world = Mat3::Identity();  // T_i^T
  };
  const MapSet& maps_;
  const ViewSet& view_set_;
  BlendOptions options_;
  std::vector<Source> sources_;
  std::vector<std::array<double, 3>> edge_norms_;  // per triangle: |a x b|, |b x c|, |c x a|
};

}  // namespace rsibr
