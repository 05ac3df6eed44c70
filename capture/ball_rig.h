// The geometry of the on-set ball rig: analytic spheres for the balls (exact normals) and a
// triangle mesh (traced with Embree, core/ray_scene.h) for what is not a ball: a stand pole under
// each ball down to the ground plane y = 0, and, per view, a proxy of the camera body and the
// photographer standing behind it, so the camera's reflection appears in the chrome ball as in
// real photos. World frame: +Y up, metres.
#pragma once

#include "capture/camera_poses.h"
#include "capture/synth_scene.h"
#include "core/mesh.h"

#include <optional>
#include <vector>

namespace rsibr {

struct RigMesh {
  Mesh mesh;
  std::vector<Vec3> albedo;  // Lambert albedo per triangle
};

// Proxy sizes (camera frame of the pose: x right, y down, z forward; the camera centre is the
// entrance pupil at the origin): a camera body box 14 x 10 x 8 cm behind the pupil, a head and a
// torso box behind and below it. Nothing lies in front of the pupil (z > 0), so the proxy never
// blocks the camera's own view.
inline constexpr double kCameraBodyAlbedo = 0.04, kPhotographerAlbedo = 0.25, kStandAlbedo = 0.08;
inline constexpr double kStandRadius = 0.012;

// The stand (when scene.stand), the clutter (scene.clutter) and, when `pose` is given and
// scene.photographer, its proxy.
RigMesh build_rig_mesh(const SynthScene& scene, const CameraPose* pose);

// Nearest t > t_min where the ray o + t d (d unit) meets the sphere (centre c, radius r), computed
// from the closest-approach vector (accurate when |o - c| >> r); nullopt when it misses.
std::optional<double> intersect_sphere(const Vec3& o, const Vec3& d, const Vec3& c, double r, double t_min = 0);

}  // namespace rsibr
