// The blend engine: a map set and its blend rule (runtime/blend.h gives the rule's definition, steps
// 1-6), evaluated by one per-texel kernel for a whole destination map (map) or for one (viewer
// direction, normal) pair (radiance). Every CPU path uses it: the blend verb and Python's blend,
// the renderer's two modes, the viewer's paper mode. The viewer's GLSL (runtime/map_shader.h)
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
// At a footprint (radiance with a Footprint: the renderer's pixels, mixed-resolution sets): each
// located source is read at the level of detail its footprint covers, lambda = log2 of the footprint's
// extent in the source's texels (the disc points of the central directions of n, n + dn_dx and
// n + dn_dy), trilinearly from the source's MIP pyramid (level l: the means of level l-1's texels it
// covers, validity and confidence alike, so a texel outside the disc never bleeds in and a tap
// renormalises by the valid share). lambda = 0 is the kernel's bilinear tap exactly.
//
// Mixed-resolution sets (the MIP-mask blend): a source's native size nu (MapView attribute
// "nativeSize": texels across its disc where they were measured, e.g. a ball's image diameter in
// pixels; absent: the map width W) says from which level of detail l_i = max(0, log2(W / nu)) its
// map holds real detail. When the sources' l_i differ by more than 1/2, each gets an authored mask
// pyramid (core/mask_pyramid.h):
//   m_i(l)(texel) = min over the level-0 texels it covers of c_i (confidence, 1 without a channel,
//                   0 outside the disc) * clamp(l - l_i + 1, 0, 1)
// and at a lookup with levels of detail lambda_i and disc points p_i, a_i <- a_i s_i with
//   s_i = m_i(lambda_i, p_i) + 1 - max_j m_j(lambda_j, p_j)   (over the located sources with a_j > 0):
// the sharpest source wherever it fully covers the lookup at that level of detail; where no source
// is sharp enough (max m = 0) every s_i is 1 and the blend is the plain one; in between it moves
// smoothly with lambda and p. Sets whose sources share a resolution (every computed set) have
// s_i = 1: their blends are unchanged. map() of a mixed set evaluates radiance() per texel with the
// destination texel's footprint (exact warps; request.warp and source_weights are not used).
//
// Thread safety: every method is const and may be called from many threads at once.
#pragma once

#include "formats/map_set.h"
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

  // A lookup's footprint: how the normal changes across one pixel (world; the differences to the
  // neighbouring pixels' normals). Zero: a point.
  struct Footprint {
    Vec3 dn_dx = Vec3::Zero(), dn_dy = Vec3::Zero();
  };
  // radiance() at a footprint (the header comment: MIP levels, and the MIP-mask blend of
  // mixed-resolution sets). A zero footprint of a set that is not mixed gives radiance() exactly.
  Vec3 radiance(const ViewWeights& located, const Vec3& v, const Vec3& n, const Footprint& footprint,
                double* weight = nullptr) const;

  // Whether the set's sources differ in resolution (native sizes more than a factor sqrt 2 apart).
  bool mixed_resolution() const { return mixed_; }
  // Source index's level of real detail l_i = max(0, log2(W / native size)).
  double detail_level(int index) const { return detail_levels_.at(std::size_t(index)); }

  // The destination map for view_dir with frame world_from_view_for(view_dir, up) (runtime/blend.h).
  // Throws std::invalid_argument for a zero or non-finite view_dir, a bad size, or a warp that does
  // not support the destination size.
  BlendResult map(const Vec3& view_dir, const Vec3& up, const MapRequest& request = {}) const;
  // The same into `out`, reusing its images where their size and type match (a caller that blends
  // every frame keeps one BlendResult: no allocation and no first-touch page faults per frame). The
  // images are written in place, so any cv::Mat sharing their data sees the new frame.
  void map(const Vec3& view_dir, const Vec3& up, const MapRequest& request, BlendResult& out) const;

  const MapSet& maps() const { return maps_; }
  const ViewSet& view_set() const { return view_set_; }
  const BlendRule& rule() const { return rule_; }

  struct Source;  // one view in the kernel's layout (blend_engine.cpp)

 private:
  const Source& source(int index) const;          // built on first use (thread-safe)
  const Source& source_pyramid(int index) const;  // with its coarser levels (and mask), on first use
  Vec3 radiance_at(const ViewWeights& located, const Vec3& v, const Vec3& n, const Footprint* footprint,
                   double* weight) const;
  BlendResult mixed_map(const Vec3& view_dir, const Vec3& up, int width, int height) const;
  const MapSet& maps_;
  const ViewSet& view_set_;
  BlendRule rule_;
  struct Cache;
  std::unique_ptr<Cache> cache_;
  std::vector<std::array<double, 3>> edge_norms_;  // per triangle: |a x b|, |b x c|, |c x a|
  std::vector<double> detail_levels_;              // per source: l_i
  bool mixed_ = false;
};

}  // namespace rsibr
