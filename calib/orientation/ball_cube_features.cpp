#include "calib/orientation/ball_cube_features.h"

#include "calib/extraction/sphere_map_extraction.h"
#include "core/parallel.h"
#include "hdr/merge.h"

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <stdexcept>

namespace rsibr {

namespace {

struct BallGeometry {
  Vec3 axis, centre;
  double limit;    // max angle of a used pixel's ray from the axis, radians
  double cos_cam;  // cos(camera_mask_deg)
};

// The pixel that shows the reflected direction r (camera frame, unit), or nullopt when r is not
// seen in the usable part of the ball.
std::optional<Vec2> pixel_of(const LensModel& lens, const BallGeometry& g, const Vec3& r) {
  if (r.dot(-g.axis) > g.cos_cam) return std::nullopt;  // the camera's own reflection
  const Vec3 start = r - g.axis;
  if (!(start.norm() > 1e-9)) return std::nullopt;
  const auto n = reflection_normal(g.centre, r, start);
  if (!n) return std::nullopt;
  const Vec3 p = g.centre + *n;
  if (!((-p).dot(*n) > 0)) return std::nullopt;  // faces away from the camera
  if (angle_between(p, g.axis) > g.limit) return std::nullopt;
  const Vec2 q = lens.project(p);
  if (!q.allFinite() || !lens.in_image(q, 0.5)) return std::nullopt;
  return q;
}

// Angle (radians) the reflected direction turns per pixel at q: the image's Jacobian |dr/dq| (the
// larger of the two axes), by finite differences of half a pixel.
double radians_per_pixel(const LensModel& lens, const BallGeometry& g, double sin_alpha, const Vec2& q) {
  auto refl = [&](const Vec2& p) {
    return reflect_off_ball<double>(lens.unproject(p).normalized(), g.axis, sin_alpha).normalized().eval();
  };
  const Vec3 r = refl(q);
  return 2 * std::max(angle_between(r, refl(q + Vec2(0.5, 0))), angle_between(r, refl(q + Vec2(0, 0.5))));
}

int dominant_face(const Vec3& r) {
  int k = 0;
  for (int i = 1; i < 3; ++i)
    if (std::abs(r[i]) > std::abs(r[k])) k = i;
  return 2 * k + (r[k] < 0 ? 1 : 0);
}

BallGeometry geometry_of(const BallCone& cone, const BallFeatureOptions& options) {
  if (!(cone.half_angle > 0 && cone.half_angle < kPi / 2) || !cone.axis.allFinite() || !(cone.axis.norm() > 0))
    throw std::invalid_argument("ball features: invalid ball cone");
  BallGeometry g;
  g.axis = cone.axis.normalized();
  g.centre = g.axis / std::sin(cone.half_angle);
  g.limit = options.max_radius_fraction * cone.half_angle;
  g.cos_cam = std::cos(options.camera_mask_deg * kPi / 180);
  return g;
}

}  // namespace

Vec3 CubeFace::direction(double u, double v) const {
  const double c = (size - 1) / 2.0;
  return (axis + step * (u - c) * right + step * (v - c) * down).normalized();
}

std::optional<Vec2> CubeFace::texel(const Vec3& r) const {
  const double z = r.dot(axis);
  if (!(z > 1e-9)) return std::nullopt;
  const double c = (size - 1) / 2.0;
  return Vec2(c + r.dot(right) / (z * step), c + r.dot(down) / (z * step));
}

std::optional<BallPixel> ball_pixel_of(const LensModel& lens, const BallCone& cone, const BallFeatureOptions& options,
                                       const Vec3& r, bool with_angle) {
  const BallGeometry g = geometry_of(cone, options);
  const auto q = pixel_of(lens, g, r);
  if (!q) return std::nullopt;
  if (!with_angle) return BallPixel{*q, lens.unproject(*q).normalized(), 0};
  const double per_px = radians_per_pixel(lens, g, std::sin(cone.half_angle), *q);
  if (!std::isfinite(per_px)) return std::nullopt;
  return BallPixel{*q, lens.unproject(*q).normalized(), per_px};
}

std::vector<CubeFace> ball_cube_faces(const cv::Mat& image, const cv::Mat& flags, const LensModel& lens,
                                      const BallCone& cone, const BallFeatureOptions& options,
                                      const CubeFeatureOptions& cube, unsigned char clipped_mask) {
  if (image.type() != CV_32FC3 || image.cols != lens.width() || image.rows != lens.height())
    throw std::invalid_argument("ball features: the image must be float RGB of the lens model's size");
  if (!flags.empty() && (flags.type() != CV_8UC1 || flags.size() != image.size()))
    throw std::invalid_argument("ball features: the flags must be 8-bit, one channel, of the image's size");
  if (!(cube.face_fov_deg >= 90 && cube.face_fov_deg < 170) || !(cube.texel_scale > 0))
    throw std::invalid_argument("ball features: face field of view must be in [90, 170) degrees, texel scale > 0");
  const BallGeometry g = geometry_of(cone, options);
  // The ball's radius in pixels: the mean distance of its outline from its centre's pixel.
  const Vec2 c_px = lens.project(g.axis);
  double rho = 0;
  const std::vector<Vec2> outline = cone_outline(cone, lens, 16);
  for (const Vec2& p : outline) rho += (p - c_px).norm() / outline.size();
  if (!(rho > 0) || !std::isfinite(rho)) throw std::invalid_argument("ball features: the ball is not in the image");
  const double half = std::tan(cube.face_fov_deg * kPi / 360);
  const double texel = cube.texel_scale * 2 / rho;
  const int n = static_cast<int>(std::clamp(std::ceil(2 * half / texel), cube.min_face_size, cube.max_face_size));
  const Vec3 ex(1, 0, 0), ey(0, 1, 0), ez(0, 0, 1);
  // Axis, right, down per face (right-handed: right x down = axis).
  const Vec3 frames[6][3] = {{ex, -ez, ey}, {-ex, ez, ey}, {ey, ex, -ez}, {-ey, ex, ez}, {ez, ex, ey}, {-ez, -ex, ey}};
  std::vector<CubeFace> faces(6);
  for (int f = 0; f < 6; ++f) {
    CubeFace& face = faces[f];
    face.axis = frames[f][0], face.right = frames[f][1], face.down = frames[f][2];
    face.size = n;
    face.step = 2 * half / n;
    face.radiance = cv::Mat(n, n, CV_32FC3, cv::Scalar::all(0));
    face.valid = cv::Mat(n, n, CV_8UC1, cv::Scalar(0));
    parallel_for_rows(n, [&](int v) {
      for (int u = 0; u < n; ++u) {
        const auto q = pixel_of(lens, g, face.direction(u, v));
        if (!q) continue;
        const int x0 = std::clamp(static_cast<int>(std::floor(q->x())), 0, image.cols - 2);
        const int y0 = std::clamp(static_cast<int>(std::floor(q->y())), 0, image.rows - 2);
        const double fx = std::clamp(q->x() - x0, 0.0, 1.0), fy = std::clamp(q->y() - y0, 0.0, 1.0);
        if (!flags.empty()) {
          const unsigned char fl = flags.at<unsigned char>(y0, x0) | flags.at<unsigned char>(y0, x0 + 1) |
                                   flags.at<unsigned char>(y0 + 1, x0) | flags.at<unsigned char>(y0 + 1, x0 + 1);
          if (fl & (clipped_mask | kOutside)) continue;
        }
        const cv::Vec3f a = image.at<cv::Vec3f>(y0, x0), b = image.at<cv::Vec3f>(y0, x0 + 1);
        const cv::Vec3f c = image.at<cv::Vec3f>(y0 + 1, x0), d = image.at<cv::Vec3f>(y0 + 1, x0 + 1);
        cv::Vec3f val;
        for (int k = 0; k < 3; ++k)
          val[k] = static_cast<float>((1 - fy) * ((1 - fx) * a[k] + fx * b[k]) + fy * ((1 - fx) * c[k] + fx * d[k]));
        if (!(std::isfinite(val[0]) && std::isfinite(val[1]) && std::isfinite(val[2]))) continue;
        face.radiance.at<cv::Vec3f>(v, u) = val;
        face.valid.at<unsigned char>(v, u) = 255;
      }
    });
  }
  return faces;
}

BallFeatures ball_cube_features(const cv::Mat& image, const cv::Mat& flags, const LensModel& lens, const BallCone& cone,
                                const BallFeatureOptions& options, const CubeFeatureOptions& cube,
                                unsigned char clipped_mask) {
  return ball_cube_feature_set(image, flags, lens, cone, options, cube, clipped_mask).features;
}

CubeFeatureSet ball_cube_feature_set(const cv::Mat& image, const cv::Mat& flags, const LensModel& lens,
                                     const BallCone& cone, const BallFeatureOptions& options,
                                     const CubeFeatureOptions& cube, unsigned char clipped_mask) {
  CubeFeatureSet set;
  set.faces = ball_cube_faces(image, flags, lens, cone, options, cube, clipped_mask);
  std::vector<CubeFace>& faces = set.faces;
  BallFeatures& out = set.features;
  // One tone map for all faces: log luminance (+ eps, 1e-3 of the mean), scaled to 8 bits over the
  // valid texels' range; invalid texels get the valid mean (no false edges at the mask's border).
  std::vector<cv::Mat> lg(6);
  double sum = 0, lo = 1e300, hi = -1e300;
  long count = 0;
  for (int f = 0; f < 6; ++f) {
    cv::Mat lum;
    cv::transform(faces[f].radiance, lum, cv::Matx13f(1.f / 3, 1.f / 3, 1.f / 3));
    cv::max(lum, 0.0, lum);
    lg[f] = lum;
  }
  double lum_sum = 0;
  for (int f = 0; f < 6; ++f)
    for (int v = 0; v < faces[f].size; ++v)
      for (int u = 0; u < faces[f].size; ++u)
        if (faces[f].valid.at<unsigned char>(v, u)) lum_sum += lg[f].at<float>(v, u), ++count;
  for (CubeFace& face : faces) face.radiance.release();
  if (count == 0) return set;
  const double eps = std::max(1e-3 * lum_sum / count, 1e-30);
  for (int f = 0; f < 6; ++f)
    for (int v = 0; v < faces[f].size; ++v)
      for (int u = 0; u < faces[f].size; ++u) {
        float& x = lg[f].at<float>(v, u);
        x = static_cast<float>(std::log(x + eps));
        if (!faces[f].valid.at<unsigned char>(v, u)) continue;
        sum += x, lo = std::min(lo, double(x)), hi = std::max(hi, double(x));
      }
  for (int f = 0; f < 6; ++f) faces[f].log_luminance = lg[f].clone();
  if (!(hi > lo)) return set;
  const double mean = sum / count;
  struct Candidate {
    float response;
    int face;
    cv::KeyPoint kp;
    cv::Mat desc;
  };
  std::vector<Candidate> cands;
  cv::Ptr<cv::SIFT> sift = cv::SIFT::create(0, 3, options.contrast_threshold);
  for (int f = 0; f < 6; ++f) {
    if (cv::countNonZero(faces[f].valid) == 0) continue;
    lg[f].setTo(mean, faces[f].valid == 0);
    cv::Mat u8;
    lg[f].convertTo(u8, CV_8U, 255.0 / (hi - lo), -lo * 255.0 / (hi - lo));
    cv::Mat dist;
    cv::distanceTransform(faces[f].valid, dist, cv::DIST_L2, 3);
    const cv::Mat detect = dist >= 2.0;
    std::vector<cv::KeyPoint> kps;
    cv::Mat desc;
    sift->detectAndCompute(u8, detect, kps, desc);
    for (std::size_t i = 0; i < kps.size(); ++i) {
      const int x = std::clamp(static_cast<int>(std::lround(kps[i].pt.x)), 0, faces[f].size - 1);
      const int y = std::clamp(static_cast<int>(std::lround(kps[i].pt.y)), 0, faces[f].size - 1);
      if (dist.at<float>(y, x) < 1.5f * kps[i].size) continue;  // the descriptor's core reaches invalid texels
      if (dominant_face(faces[f].direction(kps[i].pt.x, kps[i].pt.y)) != f) continue;  // another face owns it
      cands.push_back({kps[i].response, f, kps[i], desc.row(static_cast<int>(i))});
    }
  }
  // The strongest max_features (stable order for equal responses).
  std::stable_sort(cands.begin(), cands.end(),
                   [](const Candidate& a, const Candidate& b) { return a.response > b.response; });
  if (options.max_features > 0 && static_cast<int>(cands.size()) > options.max_features)
    cands.resize(options.max_features);
  for (const Candidate& c : cands) {
    const Vec3 r = faces[c.face].direction(c.kp.pt.x, c.kp.pt.y);
    const auto b = ball_pixel_of(lens, cone, options, r);
    if (!b) continue;
    out.directions.push_back(r);
    out.sigma.push_back(std::max(options.sigma_px * b->radians_per_pixel, 1e-6));
    out.pixels.push_back(b->pixel);
    out.rays.push_back(b->ray);
    out.descriptors.push_back(c.desc);
    set.face.push_back(c.face);
    set.face_uv.push_back(Vec2(c.kp.pt.x, c.kp.pt.y));
  }
  return set;
}

}  // namespace rsibr
