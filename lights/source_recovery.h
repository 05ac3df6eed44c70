// Recovering the light a probe lost to clipping, from the balls that saw it without clipping.
//
// A chrome ball clips a sun (or a studio light) in every bracket, so the probe lacks it
// (lights/clipped_regions.h finds where). The grey ball in the same photos is lit by it, and so is a
// glossy ball: each region becomes one compact source s (a disc: direction d_s, radius rho_s,
// power P_s = L_s Omega_s, RGB), and the sources are solved so that the balls computed from the
// probe match the captured ones in every view. For a texel i of a captured ball map (normal n_i,
// view v_i, confidence c_i, value O_i, RGB):
//
//   grey (Lambert, albedo a):  M_i = (a / pi) [ E_known(n_i) + sum_s P_s K(n_i; d_s, rho_s) ]
//   glossy (BRDF f):           M_i = G_known(i) + sum_s P_s mean_{w in cap s} f(v_i, w) max(0, n_i.w)
//
// E_known = int L_known(w) max(0, n.w) dw is the irradiance of the probe's known part (held fixed:
// quadrature over its MIP level at most `known_width` texels wide, exact energy); G_known the
// glossy ball baked from it (bake/'s FIS integrator); K the disc's mean clamped cosine
// (lights/light_source.h). Residuals are relative, r_i = sqrt(c_i) (O_i - M_i) / max(O_i, floor)
// per channel (floor: 5% of the ball's median value), so the bright and the shadowed side count
// alike, and every texel's three residuals share one Huber loss (scale: 1.5 x the MAD-estimated
// sigma of the first solve), so texels the model cannot explain (a photographer's shadow, a
// stand) do not pull the sources.
//
// A grey ball's map is fitted on a regular sub-grid of at most `texels_per_view` trusted texels per
// view, each weighted by the texels it stands for (its shading is smooth; the cost then does not
// grow with the photos' resolution).
//
// Solve: P by non-negative least squares (hdr/nnls.h; iteratively reweighted for the loss) at the
// regions' centroids; then d (and rho, when a glossy ball is seen: a grey ball cannot tell a disc
// from a point) refined jointly with P by Ceres, each d bounded to its clipped region, P >= 0.
// Uncertainty: the larger, per quantity, of the fit's covariance (ceres::Covariance, scaled by the
// residuals' variance and by the texel count over the effective count of independent observations,
// the model's errors being smooth over a ball) and the spread of leave-one-view-out solves
// (jackknife; with `known_without`, the probe's known part of each fold is the probe assembled
// without that view's chrome map, so errors the probe shares across the grey views show too), and
// at least the fit's relative residual on the texels the source lights over the source's share
// of the light there (the model's misfit: errors every view shares show only there).
//
// A region is not recovered (a note says why, and the probe keeps it as it was) when the balls
// have fewer than `min_lit_texels` trusted texels it lights (kernel above `min_lit_kernel`): no
// grey or glossy ball, the ball clipped or hidden where the source lights it.
#pragma once

#include "bake/brdf.h"
#include "core/env_map.h"
#include "formats/map_set.h"
#include "lights/clipped_regions.h"
#include "lights/light_source.h"

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace rsibr {

struct GreyBallMaps {
  std::string name;
  const MapSet* maps =
      nullptr;  // captured (confidence), world frame; texel p holds the ball's point of normal T g_normal(p)
  Vec3 albedo = Vec3::Constant(0.18);
};

struct GlossyBallMaps {
  std::string name;
  const MapSet* maps = nullptr;  // as for the grey ball
  const Brdf* brdf = nullptr;
};

struct SourceRecoveryOptions {
  int max_sources = 8;  // the regions with the largest lower bounds; the rest are noted
  bool refine = true;   // refine directions (and radii) with Ceres; false: centroids
  double radius = 0;    // rad: each source's radius when no glossy ball fits it (a point)
  int min_lit_texels = 30;
  double min_lit_kernel = 0.1;
  int known_width = 64;
  int glossy_samples = 64;  // FIS samples per texel for the glossy ball's known part
  // A grey ball's texels fitted per view: at most this many on a regular sub-grid, each weighted
  // for the texels it stands for (0: every texel). Glossy balls keep every texel (their highlights
  // are sharp). The default's measurement: docs/tradeoffs.md, "Measured choices in the code".
  int texels_per_view = 4096;
  std::uint64_t seed = 0;
  bool jackknife = true;  // the leave-one-view-out spread in the sigmas
};

// Captured against computed over one ball's trusted texels (relative RMS over texels and
// channels, weighted by confidence, no gain fitted), without and with the sources.
struct BallResidual {
  std::string ball, kind;  // kind: "grey" | "glossy"
  long texels = 0;
  double before = 0, after = 0;
  std::vector<std::string> views;
  std::vector<double> view_before, view_after;
};

struct SourceRecovery {
  std::vector<LightSource> sources;  // recovered (power may be 0 when the balls ask for nothing)
  std::vector<int> unrecovered;      // indices of regions not recovered
  std::vector<std::string> notes;    // one line per region not recovered or left out
  std::vector<BallResidual> residuals;
  double robust_sigma = 0;  // the relative residuals' MAD sigma after the first solve
  long texels = 0;          // trusted texels of the maps
  long fitted_texels = 0;   // of them, those fitted (texels_per_view)
};

// `known`: the probe without the clipped texels (they are 0), lat-long, L (the chrome ball's
// Fresnel divided out). Throws std::invalid_argument for maps without confidence; never returns a
// non-finite value.
SourceRecovery recover_sources(const EnvMap& known, const std::vector<ClippedRegion>& regions,
                               const std::vector<GreyBallMaps>& grey, const std::vector<GlossyBallMaps>& glossy,
                               const SourceRecoveryOptions& options = {},
                               const std::map<std::string, EnvMap>& known_without = {});

}  // namespace rsibr
