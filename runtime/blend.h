// Reflection-space blending: the radiance map for any view from a map set (the paper's section 3,
// with per-texel singularity fades and per-texel normalisation). This header defines it; the blend
// engine (runtime/blend_engine.h) evaluates it in single precision (warp, taps, sums), and the
// tests' oracle (tests/runtime/blend_oracle.h) evaluates it per texel in double.
//
// For a destination view d with frame T_d = world_from_view_for(d, up):
//   1. (w_0, w_1, w_2) = spherical barycentric weights of d in its view-set triangle
//      (ViewSet::locate; outside a non-surrounding set, the weights of the nearest covered point).
//   2. For every destination texel p inside the disc and every located source i with w_i > 0, the
//      source's own warp (MapView::warp, runtime/warp.h) gives its disc point p_i and rim value rho_i.
//   3. a_i(p) = w_i * fade(rho_i) * c_i(p), with c_i the source's confidence (bilinear) when the map has
//      one (and BlendOptions::use_confidence), else 1, and
//
//        fade(rho) = smoothstep(clamp(rho / rim_fade, 0, 1)),  smoothstep(t) = t^2 (3 - 2t).
//
//      rho is the z of the source normal at p_i (runtime/warp.h): for the mirror warp rho = sin(phi/2)
//      with phi the angle between p's mirror direction and -v_i (the direction the source smears over
//      its whole rim); for the normal warp rho = n . v_i (<= 0: the normal faces away from v_i and is
//      not in the source at all). Equivalently fade is a function of the source disc radius alone,
//      rho = sqrt(1 - |p_i|^2): the source is trusted fully inside radius sqrt(1 - rim_fade^2). The
//      default rim_fade = 0.4 means: mirror, full weight for phi >= 47 degrees from -v_i; normal, full
//      weight for normals >= 23.6 degrees above v_i's silhouette; source disc radius 0.917. The fade is
//      0 only at the singular direction itself (mirror) or on/behind the silhouette (normal).
//      Why rho: a source's radial resolution there is proportional to rho (d theta/d radius = 2/rho for
//      the mirror warp, 1/rho for the normal warp), so the fade trusts each source as far as it resolves
//      the direction. A wider fade removes more of the stretched rim but biases the barycentric
//      interpolation of view-dependent values toward sources seeing the texel head-on; the default
//      balances the two (measured in docs/tradeoffs.md, "Measured choices in the code").
//   4. out(p) = sum_i a_i L_i(p) / sum_i a_i (normalised PER TEXEL), weight(p) = sum_i a_i in [0, 1].
//      L_i(p) is bilinear in the source map; taps whose centres lie outside the source disc are dropped
//      and the rest renormalised.
//   5. Where sum_i a_i = 0 (every source faded there, e.g. exactly at the singular direction of the only
//      weighted source, or normals behind all three sources when d lies far outside a non-surrounding
//      set), out(p) is the sample of the least-faded located source (largest rho, ties to the first in
//      ViewWeights order, zero-weight located views included) at its clamped disc point, and weight(p)
//      is 0. Texels outside the destination disc are 0 with weight 0. No NaN or Inf is produced for
//      finite maps.
//   6. Albedo-normalised sets (MapView::albedo, core/albedo_normalisation.h): steps 1-5 blend the stored
//      L / A values; out(p) is then multiplied by A(z_p), z_p = n . d = g_normal(p).z, so every source
//      contributes L_i(p_i) A(n.d) / A(n_i.v_i): the outgoing-angle factor is re-evaluated at the
//      destination instead of being warped. A set reproduces each source at its own view either way.
#pragma once

#include "formats/map_set.h"
#include "core/view_set.h"
#include "runtime/warp.h"

#include <opencv2/core.hpp>

#include <array>

namespace rsibr {

// The rule (steps 1, 3 and 5 above): what a blend engine is built with.
struct BlendRule {
  // Width of the singularity fade in rho units (see the header comment); <= 0 disables the fade
  // (every source at full weight everywhere, the paper without its confidence fade: for tests).
  double rim_fade = 0.4;
  // Multiply each source's weight by its confidence channel (captured maps) when it has one.
  bool use_confidence = true;
  Barycentric barycentric = Barycentric::Gnomonic;
};

// What one destination map is asked for.
struct MapRequest {
  // Destination size; 0 x 0 = the map set's. Give both or neither.
  int width = 0;
  int height = 0;
  // The warp implementation; nullptr = ExactWarp. Not owned; must support the destination size.
  const Warp* warp = nullptr;
  // Also return each located source's per-texel weight a_i (BlendResult::source_weight).
  bool source_weights = false;
};

// Both, for the one-call form blend() below.
struct BlendOptions : BlendRule, MapRequest {};

struct BlendResult {
  cv::Mat rgb;           // CV_32FC3, RGB, sphere-map layout; 0 outside the disc
  cv::Mat weight;        // CV_32FC1, sum_i a_i in [0, 1]; 0 outside the disc and where the fallback was used
  Mat3 world_from_view;  // the destination frame T_d
  ViewWeights located;   // the sources and their barycentric weights
  std::array<cv::Mat, 3> source_weight;  // when requested: a_i per texel (CV_32FC1) for located.views[i]
};

// The fade of step 3, in double (the blend engine evaluates the same formula in float).
double rim_fade_weight(double rho, double rim_fade);

// The input checks of the blend engine (runtime/blend_engine.h): the map set is not empty and
// view_set has its views (throws std::invalid_argument); and view `index`'s map is a CV_32FC3 of at
// least 2 x 2 with an empty or matching CV_32FC1 confidence.
void check_blend_inputs(const MapSet& maps, const ViewSet& view_set);
void check_blend_source(const MapSet& maps, int index);

// One destination map: BlendEngine(maps, view_set, options).map(view_dir, up, options)
// (runtime/blend_engine.h; only the located sources are put in the kernel's layout). Callers that
// blend many views of one set keep an engine instead. Throws std::invalid_argument when view_set
// does not have the map set's views, when a located source's map is not CV_32FC3 (or its confidence
// not CV_32FC1 of the same size), for a bad size, a zero or non-finite view_dir, or a warp that does
// not support the destination size.
BlendResult blend(const MapSet& maps, const ViewSet& view_set, const Vec3& view_dir, const Vec3& up,
                  const BlendOptions& options = {});

}  // namespace rsibr
