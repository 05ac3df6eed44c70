#include "cli/camera_options.h"

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
      ->check(CLI::NonNegativeNumber);
}

Camera make_camera(const CameraArgs& a, const Eigen::AlignedBox3f& bounds, int k) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(a.size.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') || w <= 0 ||
      h <= 0 || w > 32768 || h > 32768)
    throw std::invalid_argument("--size: expected WxH with positive sizes, got '" + a.size + "'");
  if (!(a.fov > 0 && a.fov < 180)) throw std::invalid_argument("--fov must be in (0, 180) degrees");
  const Vec3 up = parse_vec3(a.up, "--up");
  if (!(up.norm() > 0)) throw std::invalid_argument("--up must be non-zero");
  Vec3 at;
  if (!a.at.empty()) {
    at = parse_vec3(a.at, "--at");
  } else {
    if (bounds.isEmpty()) throw std::invalid_argument("--at: the mesh is empty");
    at = bounds.center().cast<double>();
  }
  Camera c;
  if (!a.eye.empty()) {
    const Vec3 eye = parse_vec3(a.eye, "--eye");
    if (!((eye - at).norm() > 0)) throw std::invalid_argument("--eye and --at coincide");
    c = look_at(eye, at, up, a.fov, w, h);
  } else {
    const Vec3 from = parse_vec3(a.from, "--from");
    if (!(from.norm() > 0)) throw std::invalid_argument("--from must be non-zero");
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
