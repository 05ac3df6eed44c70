// The synthetic capture renderer: scene-linear radiance of the ball rig under an environment at
// infinity, seen through an mrcal lens from a camera pose.
//
// What a ray (origin o, unit direction d) returns:
//   nothing hit      L_env(d)                                   bilinear in the environment map
//   chrome ball      F(cos) * L(p, r), r = d - 2 (d.n) n, cos = -d.n, n the exact sphere normal,
//                    F the ball's Fresnel (bake/fresnel.h); the reflected ray is traced again
//                    (the other balls, the stand and the photographer appear in it), up to 4 bounces
//   grey ball        albedo * E(n) / pi                         Lambert
//   stand, proxies   albedo * E(n) / pi                         Lambert, n facing the ray
// E(n) = int L_env(w) max(0, n.w) dw is the unoccluded irradiance: read bilinearly from a
// 256 x 128 lat-long irradiance map whose texels are capture/irradiance.h's quadrature (bright texels
// at full resolution, the rest on a 128-wide MIP level). Measured accuracy against brute force over
// every texel: tests/capture/rig_renderer_test.cpp (GreyPixelEquals...).
// The balls and proxies do not shadow each other (the truth maps are those of the unoccluded balls).
//
// Pixels: n x n stratified samples, jittered per pixel by a counter-based stream keyed by (seed,
// pixel) (or at the stratum centres without jitter), averaged with equal weights (a box filter
// over the pixel's square, as a sensor integrates). Output CV_32FC3, RGB, height x width.
#pragma once

#include "capture/ball_rig.h"
#include "capture/camera_poses.h"
#include "core/env_map.h"
#include "core/lens_model.h"
#include "core/ray_scene.h"

#include "bake/fresnel.h"

#include <opencv2/core.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace rsibr {

// The irradiance map described above (lat-long, RGB, E in radiance units times sr).
EnvMap irradiance_map(const EnvMap& env, int width = 256);

struct RenderOptions {
  int supersampling = 2;  // n: n x n samples per pixel
  bool jitter = true;     // false: stratum centres (n = 1: the pixel centre)
  std::uint64_t seed = 1;
};

class RigRenderer {
 public:
  // Keeps copies of what it needs; builds the irradiance map once.
  RigRenderer(const SynthScene& scene, EnvMap env);

  // The radiance image of one view (the stand and this pose's photographer proxy in the scene).
  // `progress`, if set, gets the fraction done (from worker threads).
  cv::Mat render(const CameraPose& pose, const LensModel& lens, const RayTable& rays, const RenderOptions& options,
                 const std::function<void(double)>& progress = {}) const;

  // Radiance arriving at o from direction -d, i.e. along the ray o + t d (see above); `scene` may
  // be null (no meshes).
  Vec3 radiance(const Vec3& o, const Vec3& d, const RayScene* scene, const RigMesh* mesh, int depth = 0) const;
  Vec3 irradiance(const Vec3& n) const;
  Vec3 environment(const Vec3& d) const;

  const EnvMap& env() const { return env_; }
  const EnvMap& irradiance_env() const { return irradiance_; }

 private:
  struct Ball {
    Vec3 centre;
    double radius;
    bool chrome;
    Vec3 albedo;
    std::shared_ptr<const Fresnel> fresnel;
  };
  SynthScene scene_;
  EnvMap env_, irradiance_;
  std::vector<Ball> balls_;
};

}  // namespace rsibr
