// The blend engine: a map set and its blend rule (runtime/blend.h gives the rule's definition, steps
// 1-6), evaluated by one per-texel kernel for a whole destination map (map) or for one (viewer
// direction, normal) pair (radiance). Every CPU path uses it: the blend verb and Python's blend,
// the renderer's two modes, the viewer's paper mode. The viewer's GLSL (runtime/viewer/map_shader.h)
// is the one deliberate second implementation, tested against it.
//
// Contract of radiance(v, n) (world frame, unit v from the surface toward the viewer, unit n):
//   0. n is clamped to v's hemisphere: when n.v < 0, n <- (n - (n.v) v)/|n - (n.v) v|, the nearest
//      normal with n.v = 0 (the rim of v's sphere map). n = -v exactly takes
//      -world_from_view_for(v).col(1), the rim point (0,-1).
//   1. The located sources and weights: locate(v) (ViewSet::locate with the rule's barycentrics).
//   2. The central direction: mirror-warped sources use r = 2(n.v)n - v, normal-warped ones n, warped
//      into source i by warp_direction (runtime/warp.h, double precision).
//   3-5. The kernel (below), then the albedo factor A(n.v) for albedo-normalised sets.
// With v = a destination view d and n = T_d g_normal(p) for a destination texel p inside the disc this
// is map()'s texel p up to the warp's rounding (map() warps in float; tested).
//
// The kernel (one texel; the rule's steps 3-5): for each located source with weight w_i > 0,
// a_i = w_i fade(rho_i) c_i with the bilinear tap L_i (taps whose centres lie outside the source disc
// dropped, the rest renormalised: runtime/disc_sampler.h's definition), out = sum a_i L_i / sum a_i,
// weight = sum a_i; where the sum is 0, the least-faded located source at its disc point, weight 0.
// Taps, fades and sums are single precision. Each source is held once per engine in the kernel's
// layout (RGBA float with a one-texel border: colour and tap validity in one 16-byte load, built the
// first time the source is used; about 16 bytes a texel, 20 with a confidence channel).
//
// Thread safety: every method is const and may be called from many threads at once.
#pragma once

#include "core/map_set.h"
#include "core/view_set.h"
#include "runtime/blend.h"
#include "runtime/warp.h"

#include <memory>
#include <vector>

namespace rsibr {

class BlendEngine {
 public:
  // Keeps references: maps and view_set must outlive the engine. Checks that the set is not empty and
  // that view_set has its views (std::invalid_argument); a source's map, confidence and warp name
  // are checked when the source is first used (prepare_all checks them all now).
  BlendEngine(const MapSet& maps, const ViewSet& view_set, const BlendRule& rule = {});
  ~BlendEngine();
  BlendEngine(const BlendEngine&) = delete;
  BlendEngine& operator=(const BlendEngine&) = delete;

  // Builds every source's kernel layout now (callers that will touch all views, like the renderer's
  // per-pixel mode), with the checks.
  void prepare_all() const;

  // ViewSet::locate(v, rule.barycentric), the same result. `hint` (per caller, start at -1) holds the
  // last triangle found: when v lies strictly inside it (more than 1e-9 rad from every edge, so no
  // other triangle can contain v), the search over the set is skipped.
  ViewWeights locate(const Vec3& v, int* hint = nullptr) const;

  // Radiance (RGB, the maps' units) for unit v and unit n, both world (the contract above). weight
  // (optional) gets sum_i a_i in [0, 1].
  Vec3 radiance(const Vec3& v, const Vec3& n, double* weight = nullptr) const {
    return radiance(locate(v), v, n, weight);
  }
  // The same with located = locate(v) done by the caller.
  Vec3 radiance(const ViewWeights& located, const Vec3& v, const Vec3& n, double* weight = nullptr) const;

  // The destination map for view_dir with frame world_from_view_for(view_dir, up) (runtime/blend.h).
  // Throws std::invalid_argument for a zero or non-finite view_dir, a bad size, or a warp that does
  // not support the destination size.
  BlendResult map(const Vec3& view_dir, const Vec3& up, const MapRequest& request = {}) const;

  const MapSet& maps() const { return maps_; }
  const ViewSet& view_set() const { return view_set_; }
  const BlendRule& rule() const { return rule_; }

  struct Source;  // one view in the kernel's layout (blend_engine.cpp)

 private:
  const Source& source(int index) const;  // built on first use (thread-safe)
  const MapSet& maps_;
  const ViewSet& view_set_;
  BlendRule rule_;
  struct Cache;
  std::unique_ptr<Cache> cache_;
  std::vector<std::array<double, 3>> edge_norms_;  // per triangle: |a x b|, |b x c|, |c x a|
};

}  // namespace rsibr
