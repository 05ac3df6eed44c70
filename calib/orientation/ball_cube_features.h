// Features of the chrome ball detected in a distortion-free domain: the world reflected in the ball,
// resampled onto the six gnomonic faces of a cube in the camera frame, where a world feature looks
// the same whether the ball shows it near its centre or compressed ~10x radially near its rim. SIFT
// run on the ball's image itself (calib/orientation/ball_features.h) matches only views < ~20-30 degrees apart;
// on the cube faces it matches across wide baselines (60-120 degrees).
//
// Face f (axis a_f, right e_f, down g_f; camera frame) at texel (u, v), centre c = (N - 1) / 2:
//   r = normalize(a_f + s (u - c) e_f + s (v - c) g_f),  s = tan(fov / 2) / (N / 2)  (gnomonic).
// r -> the surface normal n whose point P = C + n reflects the camera ray into r (C = axis /
// sin(alpha), ball radius 1; calib/extraction/sphere_map_extraction.h's guarded Newton, started at the
// viewer-at-infinity normal normalize(r - axis)) -> pixel q = lens.project(P) -> bilinear lookup.
// Resolution: at the ball's centre one pixel of a ball of radius rho pixels turns the normal by
// 1/rho and the reflected ray by 2/rho, so s = 2/rho (the face size follows from the radius).
// Faces span fov = 100 degrees (5 degrees of overlap on every edge, so a descriptor near a cube
// edge sees a full neighbourhood); a keypoint is kept only on the face whose axis is r's dominant
// axis, so each direction is detected once.
// Valid texels: Newton converged, P faces the camera, P's ray within max_radius_fraction of the
// cone's angle alpha, r farther than camera_mask_deg from the direction to the camera (its own
// reflection), the pixel's bilinear taps inside the image and not flagged clipped.
// SIFT on the log luminance (one tone map for all faces) inside the valid mask eroded by the
// descriptor's support (a keypoint needs valid texels within its Gaussian core, 1.5 x its size).
// Each keypoint -> r by the gnomonic map above (exact), -> its pixel q by the same geometry (kept
// as the observation's ray, which the joint solve reflects again when the ball centre moves), and
// sigma = sigma_px * |dr/dq| at q (the image's per-pixel Jacobian; the image's pixel noise limits
// the localisation, however finely the face samples it).
#pragma once

#include "calib/balls/ball_cone.h"
#include "calib/orientation/ball_features.h"
#include "core/lens_model.h"

#include <opencv2/core.hpp>

#include <optional>
#include <vector>

namespace rsibr {

struct CubeFeatureOptions {
  double face_fov_deg = 100;  // per face (> 90: overlap)
  double texel_scale = 1.0;   // face texel = texel_scale * 2 / radius_px radians at the face centre
  double min_face_size = 32, max_face_size = 1024;
};

// The gnomonic face resampling alone (for tests and figures): face f's linear radiance and its
// validity mask (CV_32FC3, CV_8UC1 255 valid), N x N texels; face axes in the order +x -x +y -y +z -z.
struct CubeFace {
  Vec3 axis, right, down;
  int size = 0;
  double step = 0;        // s above: tan units per texel
  cv::Mat radiance;       // CV_32FC3, linear
  cv::Mat valid;          // CV_8UC1
  cv::Mat log_luminance;  // CV_32FC1: what SIFT saw (log(luminance + eps)); filled by ball_cube_feature_set only
  // The camera-frame direction of texel position (u, v) (sub-texel, gnomonic inverse).
  Vec3 direction(double u, double v) const;
  // The texel position of camera-frame direction r (gnomonic), or nullopt when r is not in front of the face.
  std::optional<Vec2> texel(const Vec3& r) const;
};
std::vector<CubeFace> ball_cube_faces(const cv::Mat& image, const cv::Mat& flags, const LensModel& lens,
                                      const BallCone& cone, const BallFeatureOptions& options = {},
                                      const CubeFeatureOptions& cube = {}, unsigned char clipped_mask = 1);

// The features with what made them: the faces (log_luminance filled, radiance released) and each
// feature's face and sub-texel position there (for calib/orientation/track_refinement.h).
struct CubeFeatureSet {
  BallFeatures features;
  std::vector<CubeFace> faces;
  std::vector<int> face;      // per feature
  std::vector<Vec2> face_uv;  // per feature, texels
};

// `image` CV_32FC3 linear RGB of the lens's size; `flags` empty or CV_8UC1 of that size (hdr/merge.h
// bits; those in `clipped_mask` invalidate a texel). Uses options' max_features (the strongest
// responses over all faces), sigma_px, max_radius_fraction, camera_mask_deg, contrast_threshold.
CubeFeatureSet ball_cube_feature_set(const cv::Mat& image, const cv::Mat& flags, const LensModel& lens,
                                     const BallCone& cone, const BallFeatureOptions& options = {},
                                     const CubeFeatureOptions& cube = {}, unsigned char clipped_mask = 1);
BallFeatures ball_cube_features(const cv::Mat& image, const cv::Mat& flags, const LensModel& lens, const BallCone& cone,
                                const BallFeatureOptions& options = {}, const CubeFeatureOptions& cube = {},
                                unsigned char clipped_mask = 1);

// Where the ball shows the reflected direction r (camera frame, unit): the pixel, its unit camera
// ray, and the angle r turns per pixel there (|dr/dq|, the larger axis). nullopt when r is not seen
// in the ball's usable part (options' max_radius_fraction and camera_mask_deg), or off the image.
// The angle per pixel costs three more reflections: without `with_angle` it is left at 0.
struct BallPixel {
  Vec2 pixel;
  Vec3 ray;
  double radians_per_pixel = 0;
};
std::optional<BallPixel> ball_pixel_of(const LensModel& lens, const BallCone& cone, const BallFeatureOptions& options,
                                       const Vec3& r, bool with_angle = true);

}  // namespace rsibr
