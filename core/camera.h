// A perspective pinhole camera for the renderers (rsibr reference, rsibr render, the viewer).
//
// Frames (docs/conventions.md): world is right-handed, +Y up. The camera frame is mrcal/OpenCV's:
// x right, y down, z forward. Pixel coordinates follow mrcal: (0, 0) is the CENTRE of the top-left
// pixel, so pixel (c, r) covers [c - 1/2, c + 1/2] x [r - 1/2, r + 1/2]. Projection of a camera-frame
// point q with q.z > 0: (fx q.x / q.z + cx, fy q.y / q.z + cy).
#pragma once

#include "core/vec.h"

#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace rsibr {

// A named camera placement (a photo's or a synthetic view's), without intrinsics.
struct CameraPose {
  std::string name;
  Vec3 eye = Vec3::Zero();                 // camera centre, world
  Mat3 world_from_cam = Mat3::Identity();  // columns: camera x (right), y (down), z (forward)
};

struct Camera {
  int width = 640;
  int height = 360;
  double fx = 500, fy = 500;               // focal lengths, pixels
  double cx = 319.5, cy = 179.5;           // principal point, pixels (mrcal convention)
  Vec3 eye = Vec3(0, 0, 3);                // camera centre, world
  Mat3 world_from_cam = Mat3::Identity();  // columns: camera x (right), y (down), z (forward) in world

  // Unit world direction of the ray through image point (px, py) (pixel units, mrcal convention).
  Vec3 ray_direction(double px, double py) const {
    return (world_from_cam * Vec3((px - cx) / fx, (py - cy) / fy, 1.0)).normalized();
  }
  Vec3 forward() const { return world_from_cam.col(2); }
  // The sphere-map view direction of the paper's mode: toward the viewer, i.e. -forward.
  Vec3 view_direction() const { return -forward(); }
  // The camera's up in world (-y of the camera frame).
  Vec3 up() const { return -world_from_cam.col(1); }
  // Image point of a world point; false when it is not strictly in front of the camera.
  bool project(const Vec3& world, Vec2* pixel) const;
};

// A camera at `eye` looking at `at` with `up` (world) projected to the image's -y, vertical field of
// view `vfov_deg` (degrees, in (0, 180)), square pixels, principal point at the image centre.
// Throws std::invalid_argument for eye == at, a non-finite input, a bad size or field of view.
// When up is parallel to the viewing direction a fixed fallback is used (the frame stays a rotation).
Camera look_at(const Vec3& eye, const Vec3& at, const Vec3& up, double vfov_deg, int width, int height);

// A camera looking along `direction` (world, from the camera toward the object; need not be unit) at
// the centre of `bounds` from far enough that the bounding sphere fills `fill` (0..1] of the smaller
// image dimension's field of view.
Camera frame_bounds(const Eigen::AlignedBox3f& bounds, const Vec3& direction, const Vec3& up, double vfov_deg,
                    int width, int height, double fill = 0.9);

// Frame k of n of a turntable: `camera` rotated about the axis through `pivot` along `axis` (world,
// right-handed) by 2 pi k / n. k = 0 returns camera unchanged.
Camera orbit(const Camera& camera, const Vec3& pivot, const Vec3& axis, int k, int n);

// "x,y,z" -> Vec3; throws std::invalid_argument("<what>: ...") for anything else (non-finite too).
Vec3 parse_vec3(const std::string& text, const std::string& what);

}  // namespace rsibr
