// Splitting the brightest texels (a sun, studio lights) off an environment, to be integrated by
// deterministic quadrature while a sampler handles the rest.
//
// Why: a sun of 1e4-1e5 x the mean radiance holds a few percent of the environment's power in a
// handful of texels. A sampler that reaches it with N stratified samples lands floor or ceil of
// N * share samples there, and that rounding is the dominant error near highlights (measured in
// docs/tradeoffs.md, "Measured choices in the code"). The split is exact:
//
//   L_o = sum_{q in B} L(q) int_{cell q} eval(wo, w) dw  +  int L_rest(w) eval(wo, w) dw
//
// with B the bright texels and L_rest the environment with B zeroed. The first term is a fixed
// k x k midpoint rule over each bright cell (uniform in solid angle; k grows when the BRDF lobe is
// narrow against the cell, so near-mirror lobes see the sun's disc, not its centre only); the
// second goes to the sampler, whose environment distribution no longer has a sun.
//
// Selection: texels of luminance >= ratio x the environment's mean luminance (over solid angle),
// at most max_count of them, brightest power (luminance x solid angle) first.
//
// Clusters: a sun enlarged to 1024 x 512 covers ~200 texels, too many to evaluate per map texel.
// For a lobe much wider than the sun, a group of bright texels within angular radius rho acts as
// one point light at its power-weighted centroid: the first-order error cancels at the centroid
// and the rest is O((rho / lobe width)^2). So the bright texels are also grouped (greedily,
// brightest first, each joining the first cluster whose seed lies within the level's radius) at
// radii of 0.5, 1, 2, 4, 8 and 16 degrees, and a map texel uses the coarsest level whose radius is
// at most kClusterFraction x the BRDF's lobe width at wo; lobes narrower than that use the texels
// themselves (with the k x k rule below).
#pragma once

#include "bake/brdf.h"
#include "bake/environment_distribution.h"
#include "bake/shading_frame.h"
#include "core/env_map.h"

#include <vector>

namespace rsibr {

struct BrightTexelOptions {
  double ratio = 10;  // <= 0 or max_count = 0 disables the split
  int max_count = 4096;
};

struct BrightTexel {
  long texel = 0;                // r * width + c of the lat-long map
  Vec3 radiance = Vec3::Zero();  // L (RGB), not multiplied by the solid angle
  double solid_angle = 0;
  double angular_size = 0;  // sqrt(solid angle), radians
  double radius = 0;        // bound on the angle from the cell's centre to any of its points
};

struct BrightCluster {
  Vec3 dir = Vec3::UnitZ();   // power-weighted centroid of the members' cell centres (world, unit)
  Vec3 power = Vec3::Zero();  // sum of L * solid angle over the members (RGB)
  double radius = 0;          // largest angle from dir to a member's cell centre
};

struct BrightClusterLevel {
  double max_radius = 0;  // radians: every member lies within this of its cluster's seed
  std::vector<BrightCluster> clusters;
};

// A cluster level is used when its max_radius <= kClusterFraction * lobe width.
inline constexpr double kClusterFraction = 0.05;

struct EnvironmentSplit {
  EnvMap remainder;  // the lat-long environment with the bright texels zeroed
  std::vector<BrightTexel> bright;
  std::vector<BrightClusterLevel> levels;  // ascending max_radius; empty when bright is
  double bright_share = 0;                 // their share of the luminance integral
};

// env must be lat-long (bake/mis_integrator.h: as_latlong).
EnvironmentSplit split_bright_texels(const EnvMap& latlong, const BrightTexelOptions& options = {});

// The coarsest cluster level whose max_radius <= kClusterFraction * lobe_width; nullptr when the
// lobe is narrower than the finest level allows.
const BrightClusterLevel* cluster_level_for(const EnvironmentSplit& split, double lobe_width);

// The first term of the split for one map texel: with the coarsest cluster level allowed by the
// lobe width at wo, sum over clusters of eval(wo, frame.to_local(dir)) * power (clusters whose centroid is
// below the horizon contribute 0); without one, sum over the bright texels of
// L(q) int_{cell q} eval(wo, frame.to_local(w)) dw by a k x k midpoint rule per cell,
// k = clamp(ceil(4 * angular_size / lobe_width(wo)), 1, 8), cells entirely below the horizon
// skipped. frame: around the normal n; `cells` is the lat-long layout the texels belong to.
Vec3 bright_texel_radiance(const Brdf& brdf, const shading::Frame& frame, const Vec3& wo, const EnvironmentSplit& split,
                           const Layout& cells);

}  // namespace rsibr
