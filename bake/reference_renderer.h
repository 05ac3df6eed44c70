// The reference render: a Monte Carlo (Embree) render of a mesh with one BRDF under a distant
// environment, seen by a perspective camera. The ground truth that runtime renders are compared with.
//
// Frames and units: world is right-handed, +Y up; the camera is core/camera.h's (mrcal: x right,
// y down, z forward; pixel (c, r) covers [c - 1/2, c + 1/2] x [r - 1/2, r + 1/2]). The environment
// gives L_i(w), the radiance arriving FROM world direction w (core/env_map.h), at infinity: every
// point of the mesh sees the same environment. Output is scene-linear radiance, RGB.
//
// What a pixel holds: the mean over its samples (spp stratified sub-pixel positions) of the radiance
// arriving at the eye along the sample's ray:
//   - the ray misses the mesh: L_i(d) for the ray direction d (background = environment; bilinear
//     lookup), or 0 (background = black);
//   - the ray hits the mesh at x with shading normal n (vertex normals interpolated) and
//     v = -d (unit, from x toward the eye):
//
//       shadows OFF (the per-texel contract of bake/integrator.h, so that a distant sphere mesh seen
//       by a distant camera reproduces a baked map; runtime renders must match this mode):
//         L_o(x, v) = int_S2 L_i(w) f_r(v, w, n) max(0, n.w) dw        (no occlusion, no bounces)
//
//       shadows ON (the mesh is opaque):
//         L_o(x, v) = int_S2 L(x, w) f_r(v, w, n) max(0, n.w) dw,  L(x, w) = L_i(w) when the ray
//         from x along w escapes, else (bounces > 1) the radiance L_o(y, -w) leaving the first hit
//         y toward x, recursively up to `bounces` surface interactions (0 beyond them).
//
// Estimator: at every surface interaction, light_samples environment samples
// (bake/environment_distribution.h, luminance x solid angle) and light_samples BRDF samples combined
// with the balance heuristic, exactly as bake/mis_integrator.h; the environment radiance of lighting
// is the texel value (piecewise constant, like the integrators), so a sun 1e5 times the sky gives
// bounded sample weights: no fireflies, no lost energy. With bounces > 1 the first BRDF sample of a
// vertex that hits the mesh continues the path (its throughput is the BRDF's sample weight).
//
// Normals (no NaN/Inf for any view):
//   - Both faces reflect: the geometric normal n_g is turned toward the viewer, and the shading
//     normal n is turned to n_g's side (a ray hitting a triangle's back side sees the side it hit,
//     and a winding that disagrees with the vertex normals does not matter).
//   - When v is still on or below the shading hemisphere (v.n < kMinViewCosine, e.g. interpolated
//     normals at a silhouette), n is tilted toward v by the smallest rotation that makes
//     v.n = kMinViewCosine; when n = -v exactly, n_g is used.
//   - Shadows ON: a direction w on the other side of the surface than the viewer (w.n_g <= 0) is
//     blocked by the surface itself, even when it is above the shading hemisphere. Shadow and
//     continuation rays start at x offset by ray_epsilon along n_g (toward w's side).
//
// Alpha: the fraction of the pixel's samples whose camera ray hits the mesh (coverage), in [0,1].
// With background = black the RGB is premultiplied by it; with background = environment the misses
// carry the environment.
//
// Determinism: each pixel draws its random numbers from its own counter-based stream keyed by
// (seed, pixel index) (integrator_detail::TexelRng); pixels are written independently and counts
// reduced per row in a fixed order, so the same inputs and seed give the same bytes whatever the
// thread count.
#pragma once

#include "bake/brdf.h"
#include "bake/bright_texels.h"
#include "bake/environment_distribution.h"
#include "core/camera.h"
#include "core/env_map.h"
#include "core/ray_scene.h"

#include <opencv2/core.hpp>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace rsibr {

enum class Background { Environment, Black };

// "env" | "black"; throws std::invalid_argument otherwise.
Background parse_background(const std::string& text);
std::string to_string(Background b);

struct ReferenceOptions {
  int spp = 16;           // camera samples per pixel (stratified: rotated Hammersley set per pixel)
  int light_samples = 1;  // per surface interaction: this many environment AND BRDF samples (MIS)
  std::uint64_t seed = 0;
  bool shadows = true;  // false: the baked-map contract (no occlusion, no bounces)
  int bounces = 1;      // surface interactions per path (>= 1); only used with shadows
  Background background = Background::Environment;
  // Offset of secondary rays, world units; <= 0: 1e-4 x the scene's extent (the larger of the
  // bounds' diagonal and the largest coordinate magnitude), which the float positions resolve.
  double ray_epsilon = 0;
};

// The smallest cosine between the view and the (tilted) shading normal; see the header comment.
inline constexpr double kMinViewCosine = 1e-3;

struct ReferenceImage {
  cv::Mat rgb;           // CV_32FC3, RGB radiance, camera.height x camera.width
  cv::Mat alpha;         // CV_32FC1, coverage in [0,1]
  long samples = 0;      // camera samples (pixels x spp)
  long hits = 0;         // camera samples that hit the mesh
  long shadow_rays = 0;  // occlusion queries (0 without shadows)
  long bounce_rays = 0;  // continuation rays (intersect queries beyond the camera's)
};

// Precomputed lighting: the environment in lat-long (other layouts resampled once, about as many
// texels), its sampling distribution and per-texel RGB, and the original map for the background.
// The sun split (bake/bright_texels.h): where a cluster level fits the BRDF's lobe at a hit, the
// bright texels are that level's clusters, each a point light with one shadow ray, and MIS samples
// the remainder (no sun noise: the dark speckles a 1e4 sun leaves at 64 spp are gone); for lobes
// too narrow for any level, MIS samples the whole environment.
class ReferenceLighting {
 public:
  explicit ReferenceLighting(const EnvMap& env);
  // L_i(w) as lighting sees it: the lat-long texel containing w (piecewise constant).
  const Vec3& radiance(long texel) const { return radiance_[std::size_t(texel)]; }
  const EnvironmentDistribution& distribution() const { return dist_; }
  // The same without the bright texels, and its distribution.
  const Vec3& remainder_radiance(long texel) const { return remainder_radiance_[std::size_t(texel)]; }
  const EnvironmentDistribution& remainder_distribution() const { return remainder_dist_; }
  const EnvironmentSplit& split() const { return split_; }
  // L_i(d) seen directly (bilinear in the original layout).
  Vec3 background(const Vec3& d) const;

 private:
  EnvMap original_, latlong_;
  EnvironmentDistribution dist_;
  std::vector<Vec3> radiance_;
  EnvironmentSplit split_;
  EnvironmentDistribution remainder_dist_;
  std::vector<Vec3> remainder_radiance_;
};

// Renders the image (see the contract above). Throws std::invalid_argument for bad options
// (spp, light_samples, bounces < 1). `progress`, if set, is called from worker threads with the
// number of rows done so far (monotone per call, not ordered across threads).
ReferenceImage render_reference(const RayScene& scene, const Brdf& brdf, const ReferenceLighting& lighting,
                                const Camera& camera, const ReferenceOptions& options,
                                const std::function<void(int)>& progress = {});

// The same, building the lighting from `env` (any layout) first; for one-off renders.
ReferenceImage render_reference(const RayScene& scene, const Brdf& brdf, const EnvMap& env, const Camera& camera,
                                const ReferenceOptions& options, const std::function<void(int)>& progress = {});

}  // namespace rsibr
