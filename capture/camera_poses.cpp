#include "capture/camera_poses.h"

#include "capture/sensor_noise.h"
#include "core/camera.h"
#include "core/view_set.h"

#include <cmath>
#include <cstdio>

namespace rsibr {
namespace {

// Look at `at` with world up, turn right by pan about the world's vertical (a rotation of -pan about
// +Y), by yaw about the camera's y axis (down), then roll about z.
Mat3 aim(const Vec3& eye, const Vec3& at, double roll_deg, double yaw_deg, double pan_deg = 0) {
  const Camera c = look_at(eye, at, Vec3(0, 1, 0), 60, 64, 64);
  return Eigen::AngleAxisd(-pan_deg * kDeg, Vec3::UnitY()).toRotationMatrix() * c.world_from_cam *
         Eigen::AngleAxisd(yaw_deg * kDeg, Vec3::UnitY()).toRotationMatrix() *
         Eigen::AngleAxisd(roll_deg * kDeg, Vec3::UnitZ()).toRotationMatrix();
}

Vec3 direction(double azimuth_deg, double elevation_deg) {
  const double a = azimuth_deg * kDeg, e = elevation_deg * kDeg;
  return Vec3(std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a));
}

}  // namespace

std::vector<CameraPose> plan_camera_poses(const SynthScene& scene) {
  std::vector<CameraPose> out;
  for (std::size_t p = 0; p < scene.views.size(); ++p) {
    const SynthViewPlan& plan = scene.views[p];
    const Vec3 at = plan.look_at.value_or(scene.rig_centre());
    std::vector<Vec3> dirs;
    if (plan.plan == "icosa") {
      const ViewSet icosa = ViewSet::icosahedron();
      for (const Vec3& v : icosa.views())
        if (std::asin(std::clamp(v.y(), -1.0, 1.0)) >= plan.min_elevation_deg * kDeg - 1e-12) dirs.push_back(v);
    } else if (!plan.azimuths_deg.empty()) {
      for (double a : plan.azimuths_deg) dirs.push_back(direction(a, plan.elevation_deg));
    } else {
      for (int i = 0; i < plan.count; ++i)
        dirs.push_back(direction(plan.azimuth0_deg + 360.0 * i / plan.count, plan.elevation_deg));
    }
    for (std::size_t i = 0; i < dirs.size(); ++i) {
      CameraPose pose;
      pose.eye = at + plan.distance_m * dirs[i];
      pose.world_from_cam = aim(pose.eye, at, plan.roll_deg, plan.yaw_deg, plan.pan_deg);
      if (plan.plan == "handheld") {
        NoiseRng rng(scene.seed, 0x4A17ull << 32 | (p << 16) | i);
        const Vec3 dp(sample_normal(rng), sample_normal(rng), sample_normal(rng));
        Vec3 axis(sample_normal(rng), sample_normal(rng), sample_normal(rng));
        axis = axis.norm() > 0 ? axis.normalized() : Vec3::UnitY();
        const double angle = plan.jitter_deg * kDeg * sample_normal(rng);
        pose.eye += plan.jitter_m * dp;
        pose.world_from_cam = Eigen::AngleAxisd(angle, axis).toRotationMatrix() *
                              aim(pose.eye, at, plan.roll_deg, plan.yaw_deg, plan.pan_deg);
      }
      char name[32];
      std::snprintf(name, sizeof name, "view%02zu", out.size());
      pose.name = name;
      out.push_back(pose);
    }
  }
  return out;
}

}  // namespace rsibr
