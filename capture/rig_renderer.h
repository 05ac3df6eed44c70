// The synthetic capture renderer: scene-linear radiance of the ball rig under an environment at
// infinity, seen through an mrcal lens from a camera pose.
//
// What a ray (origin o, unit direction d) returns:
//   nothing hit      L_env(d)                                   bilinear in the environment map
//   chrome ball      F(cos) * L(p, r), r = d - 2 (d.n) n, cos = -d.n, n the exact sphere normal,
//                    F the ball's Fresnel (bake/fresnel.h); the reflected ray is traced again
//                    (the other balls, the stand and the photographer appear in it), up to 4 bounces
//   grey ball        albedo * E_b(n) / pi                       Lambert, E_b the ball's occluded
//                    irradiance (below)
//   glossy ball      its true sphere map for this view (capture/true_sphere_map.h: bake/'s FIS
//                    integral of the BRDF) read at the normal: exact where n = v, elsewhere the view
//                    direction is taken as v (ball centre -> camera), off by up to asin(R / D)
//   stand, proxies,  albedo * E(n) / pi                         Lambert, n facing the ray
//   clutter
// E(n) = int L_env(w) max(0, n.w) dw is the unoccluded irradiance: read bilinearly from a
// 256 x 128 lat-long irradiance map whose texels are capture/irradiance.h's quadrature (bright texels
// at full resolution, the rest on a 128-wide MIP level). Measured accuracy against brute force over
// every texel: tests/capture/rig_renderer_test.cpp (GreyPixelEquals...).
// Occlusion of a grey ball (per view): each quadrature node w (capture/irradiance.h) is traced from
// the ball's surface point facing it, c + R w, against the stand, this view's photographer proxy and
// the other balls; a blocked node sees the blocker's radiance instead of the environment's. So the
// photographer's shadow and the stand's occlusion darken the grey ball as in real photos (the truth
// maps are those of the unoccluded balls). Visibility is per direction, from that one surface point
// (a parallax of R / distance to the blocker elsewhere on the ball). Stand and proxies themselves
// are shaded unoccluded.
//
// Pixels: n x n stratified samples, jittered per pixel by a counter-based stream keyed by (seed,
// pixel) (or at the stratum centres without jitter), averaged with equal weights (a box filter
// over the pixel's square, as a sensor integrates). Output CV_32FC3, RGB, height x width.
#pragma once

#include "capture/ball_rig.h"
#include "capture/camera_poses.h"
#include "capture/irradiance.h"
#include "core/env_map.h"
#include "core/lens_model.h"
#include "core/ray_scene.h"

#include "bake/fresnel.h"
#include "bake/integrator.h"

#include <opencv2/core.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace rsibr {

// The irradiance map described above (lat-long, RGB, E in radiance units times sr).
EnvMap irradiance_map(const EnvMap& env, int width = 256);

struct RigRenderOptions {
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
  cv::Mat render(const CameraPose& pose, const LensModel& lens, const RayTable& rays, const RigRenderOptions& options,
                 const std::function<void(double)>& progress = {}) const;

  // What one view's rays meet besides the environment: its meshes (scene may be null) and, per
  // ball, the occluded irradiance map of a grey ball (empty for chrome).
  struct ViewScene {
    const RayScene* scene = nullptr;
    const RigMesh* mesh = nullptr;
    std::vector<EnvMap> ball_irradiance;
    std::vector<EnvMap> ball_map;            // glossy: the view's sphere map (sphere layout, view frame)
    std::vector<Mat3> ball_world_from_view;  // glossy: its frame
  };
  ViewScene view_scene(const RayScene* scene, const RigMesh* mesh, const Vec3& eye) const;

  // Radiance arriving at o from direction -d, i.e. along the ray o + t d (see above).
  Vec3 radiance(const Vec3& o, const Vec3& d, const ViewScene& view, int depth = 0) const;
  Vec3 irradiance(const Vec3& n) const;  // unoccluded
  Vec3 environment(const Vec3& d) const;

  const EnvMap& env() const { return env_; }
  const EnvMap& irradiance_env() const { return irradiance_; }

 private:
  struct Ball {
    Vec3 centre;
    double radius;
    bool chrome, glossy;
    Vec3 albedo;
    std::shared_ptr<const Fresnel> fresnel;
  };
  Vec3 glossy_radiance(const ViewScene& view, std::size_t ball, const Vec3& n) const;
  std::unique_ptr<Integrator> fis_;  // only when there is a glossy ball
  // The first thing the ray o + t d (t > t_min) meets: ball index (>= 0), -1 for a mesh (hit in
  // *mesh_hit), -2 for nothing.
  int trace(const Vec3& o, const Vec3& d, const ViewScene& view, double* t, RayHit* mesh_hit) const;
  Vec3 shade_mesh(const ViewScene& view, const RayHit& hit, const Vec3& d) const;

  SynthScene scene_;
  EnvMap env_, irradiance_;
  IrradianceQuadrature quadrature_;
  std::vector<Ball> balls_;
};

}  // namespace rsibr
