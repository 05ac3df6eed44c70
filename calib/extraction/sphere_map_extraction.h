// Extraction: one view's linear (HDR) image + its lens model + the ball's cone (calib/balls/ball_cone.h)
// -> an ideal sphere map of the ball in that view's frame (core/sphere_map.h, docs/conventions.md), with a
// confidence channel: a captured map view (formats/map_set.h) in the same format as computed ones.
//
// View frame: z from the ball centre toward the camera centre (-axis in the camera frame), y up as
// close to the camera's up (-y of the camera frame) as z allows: cam_from_view =
// world_from_view_for(-axis, (0,-1,0)); world_from_view = world_from_cam * cam_from_view.
// Geometry in units of the ball radius (only R / D = sin(alpha) matters): centre C = axis / sin(alpha).
//
// Texel p (disc point (x, y)) is filled from the surface point P = C + n (camera frame), whose
// pixel lens.project(P) is sampled bilinearly. The knob:
//   orthographic   n = g_normal(p): the point whose normal is the texel's. Exact for a Lambertian
//                  (grey) ball, whose radiance depends on the normal only. For a mirror it shows the
//                  reflection of the camera ray w = -P/|P| instead of the viewer at infinity, off by
//                  up to asin(R / D) (the perspective error: a sphere map is orthographic, a photograph is not).
//   reflection     n such that the camera ray to P reflects into the texel's mirror direction
//                  r = g_mirror(p): n = (w(n) + r) / |w(n) + r|, Alhazen's problem, solved per
//                  texel by a guarded Newton iteration on the tangent plane (start: the orthographic
//                  normal; steps halved until the residual falls; at most 30 iterations to 1e-12).
//                  Exact for a mirror up to its Fresnel factor's angle (F(n.w) instead of F(n.z)).
// Confidence in [0, 1], the product of:
//   disc           0 outside the unit disc, for points facing away from the camera or outside the image
//   rim            smoothstep in the incidence cosine n.w from cos(rim_zero_deg) to cos(rim_full_deg):
//                  the stretched rim where one pixel covers many texels
//   limb           smoothstep in the image distance from the ball's outline, 0 at limb_margin_px/3,
//                  1 at limb_margin_px: the bilinear taps there mix in the background
//   camera         mirror maps: 0 where the reflected direction is within camera_mask_deg of the
//                  direction to the camera (its body and the photographer), ramping to 1 over
//                  camera_ramp_deg beyond
//   stand          0 where the texel's direction (reflected for mirror maps, the normal otherwise) is
//                  within stand_mask_deg of `down` (camera frame), ramping over stand_ramp_deg
//   occluders      mirror maps: 0 where the reflected ray from the texel's surface point meets one of
//                  `occluders` (calib/extraction/occluders.h: the other balls, the stands, the photographer)
//   in front       0 where the camera's ray to the texel's surface point meets one of `in_front`
//                  first (another ball nearer the camera hides that part of this one)
//   clipped        0 where any bilinear tap of any of the texel's samples has a flag in
//                  `flags` & clipped_mask (hdr/merge.h: clipped in every bracket); the confidence the
//                  texel would have had goes to the map's `clipped` channel (formats/map_set.h), which
//                  is written only when `flags` is given
// Samples (energy of small sources; mirror maps): a texel is its centre's image point read bilinearly, unless
// k x k samples on a regular grid over its cell in disc coordinates (each mapped to the image
// through the same indexing) differ by more than a factor of 2 in luminance: a feature smaller than
// the texel (a sun one pixel wide, a lamp, an edge), where the texel is their mean. The sphere map
// is equal-area in its central direction (dw = 4 dx dy for mirror maps), so the mean is over the
// texel's solid angle; samples at most half a pixel apart in the image sum the tent-reconstructed
// image closely enough to keep the feature's integral (the tent's spectrum, sinc^2, is 0 at the
// sampling frequency 2 / pixel and small around it: at spacing s the aliased error is about
// sinc^2(1 / s) per axis, 4% at 0.75 pixel, under 2% at 0.5), where the centre alone
// would read it or miss it by the sub-pixel phase (a sun's energy per view varied 40x). Smooth
// content keeps the centre's value: the texel stands for that point, and the mean differs from it
// by the curvature over the texel. k = clamp(ceil(footprint / supersample_spacing_px), 1,
// max_supersample), the footprint being the image distance to the neighbouring texels' centres.
#pragma once

#include "calib/balls/ball_cone.h"
#include "calib/extraction/occluders.h"
#include "core/lens_model.h"
#include "formats/map_set.h"

#include <opencv2/core.hpp>

#include <optional>
#include <string>
#include <vector>

namespace rsibr {

enum class SphereIndexing { orthographic, reflection };

struct ExtractOptions {
  int size = 128;  // square map
  SphereIndexing indexing = SphereIndexing::reflection;
  bool mirror = true;  // the map's warp: "mirror" (chrome) or "normal" (grey)
  double rim_zero_deg = 82, rim_full_deg = 70;
  double limb_margin_px = 1.5;
  double camera_mask_deg = 0, camera_ramp_deg = 4;
  std::optional<Vec3> down;  // camera frame; none: no stand mask
  double stand_mask_deg = 8, stand_ramp_deg = 4;
  unsigned char clipped_mask = 1;   // hdr/merge.h kClipped
  std::vector<Occluder> occluders;  // camera frame, this ball's radii (mirror maps only)
  std::vector<Occluder> in_front;   // camera frame, this ball's radii (any map)
  // Mirror maps only (a grey or glossy ball's shading has no feature smaller than a texel);
  // <= 0: the centre alone.
  double supersample_spacing_px = 0.5;
  int max_supersample = 16;
  std::string material;  // the map's rsibr.material
};

// `image` CV_32FC3 RGB linear of the lens's size; `flags` empty or CV_8UC1 of that size.
// `hidden`, if given, gets a CV_8UC1 map of the map's size: 1 where an `in_front` occluder hides
// the texel's surface point (its rgb then shows that occluder, not this ball).
// Throws std::invalid_argument for mismatched sizes or an invalid cone.
MapView extract_sphere_map(const cv::Mat& image, const cv::Mat& flags, const LensModel& lens, const BallCone& cone,
                           const Mat3& world_from_cam, const ExtractOptions& options = {}, cv::Mat* hidden = nullptr);

// The surface normal (camera frame, unit) whose point reflects the camera ray into `r` (camera
// frame, unit), for a ball of radius 1 centred at C (camera at the origin); `start` is the first
// guess. nullopt when the guarded Newton iteration does not converge.
std::optional<Vec3> reflection_normal(const Vec3& centre, const Vec3& r, const Vec3& start);

}  // namespace rsibr
