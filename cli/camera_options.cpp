#include "cli/camera_options.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace rsibr::cli {

void add_camera_options(CLI::App* verb, CameraArgs& a) {
  verb->add_option("--size", a.size, "Image size WxH in pixels")->capture_default_str();
  verb->add_option("--fov", a.fov, "Vertical field of view, degrees")->capture_default_str();
  verb->add_option("--eye", a.eye, "Camera centre x,y,z (world); default: frame the mesh");
  verb->add_option("--at", a.at, "Point looked at x,y,z (world); default: the mesh's bounds centre");
  verb->add_option("--up", a.up, "World up projected to the image's up")->capture_default_str();
  verb->add_option("--from", a.from, "Without --eye: direction from the mesh toward the camera")->capture_default_str();
  verb->add_option("--turntable", a.turntable, "Write N frames orbiting --at about --up (numbered outputs)")
      ->check(CLI::Range(0, kMaxTurntableFrames));
}

namespace {

// Scene coordinates beyond this lose the precision ray queries need (float32 in Embree): a camera
// 1e30 away is a typo, not a shot.
constexpr double kMaxCoordinate = 1e6;

Vec3 parse_point(const std::string& text, const std::string& option) {
  const Vec3 p = parse_vec3(text, option);
  if (p.cwiseAbs().maxCoeff() > kMaxCoordinate)
    throw std::invalid_argument(option + " '" + text + "': coordinates must lie within +-1e6");
  return p;
}

// A whole number of 1 to 5 digits (so no overflow), or -1.
int parse_side(const std::string& s) {
  if (s.empty() || s.size() > 5 || s.find_first_not_of("0123456789") != std::string::npos) return -1;
  return std::stoi(s);
}

// Angle in degrees between two non-zero directions.
double angle_deg(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / 3.14159265358979323846;
}

}  // namespace

Camera make_camera(const CameraArgs& a, const Eigen::AlignedBox3f& bounds, int k) {
  const std::size_t xpos = a.size.find_first_of("xX");
  const int w = xpos == std::string::npos ? -1 : parse_side(a.size.substr(0, xpos));
  const int h = xpos == std::string::npos ? -1 : parse_side(a.size.substr(xpos + 1));
  if (w <= 0 || h <= 0 || w > 32768 || h > 32768)
    throw std::invalid_argument("--size: expected WxH with sides of 1 to 32768 pixels, got '" + a.size + "'");
  if (!(a.fov >= 0.01 && a.fov <= 179)) throw std::invalid_argument("--fov must be in [0.01, 179] degrees");
  if (a.turntable > kMaxTurntableFrames)
    throw std::invalid_argument("--turntable: at most " + std::to_string(kMaxTurntableFrames) + " frames");
  const Vec3 up = parse_vec3(a.up, "--up");
  if (!(up.norm() > 0)) throw std::invalid_argument("--up must be non-zero");
  Vec3 at;
  if (!a.at.empty()) {
    at = parse_point(a.at, "--at");
  } else {
    if (bounds.isEmpty()) throw std::invalid_argument("--at: the mesh is empty");
    at = bounds.center().cast<double>();
  }
  Camera c;
  if (!a.eye.empty()) {
    const Vec3 eye = parse_point(a.eye, "--eye");
    if (!((eye - at).norm() > 1e-9 * std::max(1.0, at.norm()))) throw std::invalid_argument("--eye and --at coincide");
    if (angle_deg(at - eye, up) < 0.01 || angle_deg(at - eye, up) > 179.99)
      throw std::invalid_argument("--up " + a.up + " is parallel to the view direction from --eye to --at");
    c = look_at(eye, at, up, a.fov, w, h);
  } else {
    const Vec3 from = parse_vec3(a.from, "--from");
    if (!(from.norm() > 0)) throw std::invalid_argument("--from must be non-zero");
    if (angle_deg(from, up) < 0.01 || angle_deg(from, up) > 179.99)
      throw std::invalid_argument("--up " + a.up + " is parallel to --from " + a.from);
    Eigen::AlignedBox3f centred = bounds;
    centred.translate((at - bounds.center().cast<double>()).cast<float>());
    c = frame_bounds(centred, -from, up, a.fov, w, h);
  }
  return a.turntable > 0 ? orbit(c, at, up, k, a.turntable) : c;
}

std::string frame_path(const std::string& output, int turntable, int k) {
  if (turntable <= 0) return output;
  const std::filesystem::path p(output);
  int digits = 4;
  for (int n = turntable - 1; n >= 10000; n /= 10) ++digits;
  char number[32];
  std::snprintf(number, sizeof number, ".%0*d", digits, k);
  return (p.parent_path() / (p.stem().string() + number + p.extension().string())).string();
}

}  // namespace rsibr::cli
