// The light a scene's occluders take from a Lambertian (grey) ball, put back, so that its captured
// map is that of the ball under the environment alone (what a bake from the probe computes).
//
// A grey ball's texel shows albedo / pi * E_scene(n): the irradiance of what its surface point
// c + n sees, which is the environment except where the chrome ball beside it, another ball or the
// photographer stands. The open irradiance E_open(n) replaces those by the environment behind them:
//   E_open(n)  = sum_w L(w) max(0, n.w) dw
//   E_scene(n) = sum_w L_s(w) max(0, n.w) dw,  L_s(w) = the occluder's radiance where the ray
//                c + n + t w meets one first, L(w) otherwise
// and the corrected texel is the captured one times E_open / E_scene, per channel (the albedo and
// the exposure cancel), where the model explains the texel: captured ~ k E_scene, k the map's
// median of captured / E_scene. Where it does not (by over 2x; blended from 1.25x), chiefly at a
// sun's terminator, which the quadrature places coarsely, the difference is added in the map's
// scale instead: captured + k (E_open - E_scene). The sum runs over a lat-long quadrature of the
// probe; a direction the probe did not see (weight below min_weight) is left out of both sums
// (nothing is known to restore).
// The occluders' radiance:
//   mirror ball     F(cos) L(r), r the direction reflected at the hit point (F = 1 when the probe
//                   holds F L, i.e. no Fresnel was divided out of it)
//   lambert ball    albedo E_open(m) / pi at the hit point's normal m
//   seen by chrome  the photographer and the camera: the probe's L(w) plus what the same view's
//                   chrome ball sees beyond the far environment toward the hit point h (the ray's
//                   closest approach to the capsule's axis), D(u) = chrome(u) / F - probe(u),
//                   u = h - chrome centre, the mean of the chrome texels in u's quadrature cell
//                   (the texel of u where the cell holds none) against the probe read at the
//                   texels' footprint. Where the capsule is empty D is resampling noise about 0;
//                   where a body stands L + D = body + L(w) - L(u), exact when what it hides looks
//                   alike from both balls. A chrome texel clipped in every bracket, within 2
//                   texels of one, or brighter than 4 E_max / pi (no lit diffuse body is) counts
//                   as D = 0 (light, not a body); one showing another ball in front, or where the
//                   grey ball itself stands in the chrome ball's way toward h, is not read (that
//                   direction restores nothing)
// The probe must hold the whole light, the light clipped in every view included (the pipeline
// passes lights/recovered_probe.h's): the ratio is the photographer's light over all of it, and a
// probe short of a clipped sun overstates it (2-3x where the sun is 60% of the light).
// Frames and units: the camera frame of the view (x right, y down, z forward), lengths in radii of
// the grey ball, as calib/extraction/occluders.h; directions of the probe and the maps in their own frames.
#pragma once

#include "bake/fresnel.h"
#include "calib/balls/ball_cone.h"
#include "calib/extraction/occluders.h"
#include "core/env_map.h"
#include "formats/map_set.h"

#include <opencv2/core.hpp>

#include <vector>

namespace rsibr {

struct OccluderLight {
  Occluder shape;  // camera frame, the grey ball's radii
  enum Source { mirror_ball, lambert_ball, seen_by_chrome } source = seen_by_chrome;
  double albedo = 0.5;  // lambert_ball
};

// The open environment as a quadrature: a lat-long probe (world frame) and its summed confidence.
struct OpenLight {
  EnvMap env;   // lat-long, RGB
  EnvMap fine;  // the probe itself, with its weight: what a chrome texel is compared with
  cv::Mat fine_weight;
  double min_weight = 1e-3;
  cv::Mat seen;            // CV_8UC1: 1 where the probe's weight reached min_weight
  cv::Mat solid_angle;     // CV_64FC1, per texel
  EnvMap irradiance;       // lat-long, E_open at each texel's direction (for lambert balls)
  const Fresnel* fresnel;  // the chrome's, divided out of the probe; null: the probe holds F L
};

// The probe reduced to a `width` x width/2 quadrature (area-weighted), its coverage and irradiance.
// `weight` is the probe's summed confidence (calib/probe/probe.h), of the probe's size.
OpenLight open_light(const EnvMap& probe, const cv::Mat& weight, const Fresnel* fresnel, int width = 64,
                     double min_weight = 1e-3);

struct OccludedLight {
  cv::Mat ratio;           // CV_32FC3: E_open / E_scene per texel (1 outside the disc)
  double mean_stops = 0;   // mean |log2| of the luminance ratio over the disc's confident texels
  double max_stops = 0;    // largest
  double clamp_stops = 1;  // ratios are clamped to 2^+-clamp_stops
};

// The ratio for one grey map (orthographic indexing, calib/extraction/sphere_map_extraction.h) extracted from
// the view whose camera has `world_from_cam`, the ball's cone `grey`; `chrome` is the same view's
// chrome map (mirror, reflection indexing) with its centre `chrome_centre` (camera frame, grey
// radii), or null (seen_by_chrome occluders then restore nothing); `chrome_hidden` (empty, or
// CV_8UC1 of the chrome map's size, calib/extraction/sphere_map_extraction.h) marks its texels that show
// another ball in front of it, which are not read.
OccludedLight occluded_light(const MapView& grey, const Mat3& world_from_cam, const BallCone& grey_cone,
                             const std::vector<OccluderLight>& occluders, const OpenLight& light, const MapView* chrome,
                             const Vec3& chrome_centre, const cv::Mat& chrome_hidden = {});

// grey.rgb times the ratio, per channel.
void restore_occluded_light(MapView& grey, const OccludedLight& r);

}  // namespace rsibr
