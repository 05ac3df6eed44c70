#include "core/camera.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace rsibr {

bool Camera::project(const Vec3& world, Vec2* pixel) const {
  const Vec3 q = world_from_cam.transpose() * (world - eye);
  if (!(q.z() > 0)) return false;
  *pixel = Vec2(fx * q.x() / q.z() + cx, fy * q.y() / q.z() + cy);
  return true;
}

Camera look_at(const Vec3& eye, const Vec3& at, const Vec3& up, double vfov_deg, int width, int height) {
  if (!eye.allFinite() || !at.allFinite() || !up.allFinite())
    throw std::invalid_argument("camera: eye, at and up must be finite");
  if ((at - eye).norm() <= 0) throw std::invalid_argument("camera: eye and at coincide");
  if (!(vfov_deg > 0 && vfov_deg < 180))
    throw std::invalid_argument("camera: field of view must be in (0, 180) degrees");
  if (width <= 0 || height <= 0) throw std::invalid_argument("camera: image size must be positive");
  // The view frame of world_from_view_for(-forward, up) has x right, y up, z toward the viewer;
  // the camera frame is x right, y down, z forward: flip y and z.
  const Mat3 view = world_from_view_for(eye - at, up);
  Camera c;
  c.width = width;
  c.height = height;
  c.world_from_cam.col(0) = view.col(0);
  c.world_from_cam.col(1) = -view.col(1);
  c.world_from_cam.col(2) = -view.col(2);
  c.eye = eye;
  c.fy = 0.5 * height / std::tan(0.5 * vfov_deg * kPi / 180.0);
  c.fx = c.fy;
  c.cx = 0.5 * (width - 1);
  c.cy = 0.5 * (height - 1);
  return c;
}

Camera frame_bounds(const Eigen::AlignedBox3f& bounds, const Vec3& direction, const Vec3& up, double vfov_deg,
                    int width, int height, double fill) {
  if (bounds.isEmpty()) throw std::invalid_argument("camera: cannot frame an empty mesh");
  if (!(direction.norm() > 0) || !direction.allFinite())
    throw std::invalid_argument("camera: framing direction must be finite and non-zero");
  if (!(fill > 0 && fill <= 1)) throw std::invalid_argument("camera: fill must be in (0, 1]");
  const Vec3 centre = bounds.center().cast<double>();
  const double radius = std::max(0.5 * double(bounds.diagonal().norm()), 1e-9);
  // Half field of view of the smaller image dimension; the sphere of radius R at distance D
  // subtends asin(R / D).
  const double half_v = 0.5 * vfov_deg * kPi / 180.0;
  const double half_h = std::atan(std::tan(half_v) * double(width) / double(height));
  const double half = std::min(half_v, half_h) * fill;
  const double distance = radius / std::sin(half);
  return look_at(centre - direction.normalized() * distance, centre, up, vfov_deg, width, height);
}

Camera orbit(const Camera& camera, const Vec3& pivot, const Vec3& axis, int k, int n) {
  if (n <= 0) throw std::invalid_argument("camera: turntable frame count must be positive");
  if (!(axis.norm() > 0)) throw std::invalid_argument("camera: turntable axis must be non-zero");
  if (k % n == 0) return camera;
  const Mat3 R = Eigen::AngleAxisd(2.0 * kPi * double(k) / double(n), axis.normalized()).toRotationMatrix();
  Camera c = camera;
  c.eye = pivot + R * (camera.eye - pivot);
  c.world_from_cam = R * camera.world_from_cam;
  return c;
}

Vec3 parse_vec3(const std::string& text, const std::string& what) {
  std::istringstream in(text);
  Vec3 v;
  char comma1 = 0, comma2 = 0;
  if (!(in >> v.x() >> comma1 >> v.y() >> comma2 >> v.z()) || comma1 != ',' || comma2 != ',')
    throw std::invalid_argument(what + ": expected x,y,z, got '" + text + "'");
  in >> std::ws;
  if (!in.eof()) throw std::invalid_argument(what + ": trailing text in '" + text + "'");
  if (!v.allFinite()) throw std::invalid_argument(what + ": not finite: '" + text + "'");
  return v;
}

}  // namespace rsibr
