// Feature tracks re-located by patch alignment on the cube faces (calib/orientation/ball_cube_features.h).
// SIFT places a keypoint to ~0.25 px; with ~500 features per view that noise is the orientation
// error's floor (~0.05 degrees on a 400-px ball). Once a first solve knows the rotations to a small
// fraction of a texel, every observation of a track is re-located against one reference
// observation of it (the sharpest: the smallest SIFT sigma), in the manner of KLT tracking:
//
//   template  T_i = L_A(a + x_i)       x_i on a (2h+1)^2 texel grid around A's keypoint a (its face)
//   samples   m_i = the texel of B's face showing what A's texel a + x_i shows: A's texel -> its
//             pixel (through A's ball as detected, which made the faces) -> the world direction
//             (through A's ball as refined by the first solve, and R_A) -> B's pixel (B's refined
//             ball) -> B's texel (B's detected ball); exact on the grid {-h, 0, h}^2, biquadratic
//             between. The patch takes the shape the views' geometry gives it, and the
//             outline's error (up to 2 px of radius, which distorts the faces) cancels.
//   minimise  sum_i (g L_B(m_i + t) + b + c . x_i - T_i)^2   over the shift t (texels), gain g, bias
//             b and ramp c (log luminance: exposure, and the mirror's Fresnel, which grows toward
//             the rim: without the ramp a shift took up its gradient and the views drifted around
//             the ball; measured in docs/tradeoffs.md, "Measured choices in the code")
//
// by Gauss-Newton from B's own keypoint; B's observation becomes m_0 + t, turned into its pixel,
// ray and direction through the ball (calib/orientation/ball_cube_features.h ball_pixel_of). The reference keeps
// its direction. Its keypoint's own error is no longer in the track (its partners are placed
// relative to its patch, not to SIFT's corner); its patch's noise is, through each partner's
// alignment, so the reference gets the median of its partners' sigmas.
//
// Std dev: C = s^2 (J^T J)^-1 (s^2 the residual variance over n - 6 degrees of freedom), the shift
// block's larger eigenvalue, scaled by 1 / |det dq/duv| where the face samples the image more finely
// than its pixels (neighbouring texels then share their noise), turned into an angle by the texel's
// angular size there, plus floor_px of the image's pixels in quadrature (what the noise model leaves
// out: interpolation, the pixel-locking of sub-texel shifts; 0.03 px makes the orientations'
// (error/sigma)^2 ~1 on rendered views, docs/tradeoffs.md "Orientation").
// An alignment is dropped when a sample leaves B's valid texels, when it does not converge, when it
// ends more than max_shift_texels from B's keypoint, or when the patches' normalised
// cross-correlation is below min_ncc. A partner that failed is dropped from a track whose other
// partners were re-located (its keypoint refers to another point); a track where none was keeps
// its SIFT observations unchanged.
#pragma once

#include "calib/orientation/ball_cube_features.h"
#include "calib/orientation/orientation_solve.h"

#include <vector>

namespace rsibr {

struct TrackRefinementOptions {
  int half_size = 7;  // h: the patch is (2h + 1)^2 texels
  int max_iterations = 30;
  double max_shift_texels = 2;
  double min_ncc = 0.8;
  double floor_px = 0.03;  // in the image's pixels: what the noise model leaves out (interpolation, pixel-locking)
};

struct TrackRefinementReport {
  int tracks_refined = 0;        // tracks with >= 1 re-located partner
  int observations_refined = 0;  // re-located observations, references included
  int observations_dropped = 0;
  double median_sigma_ratio = 0;  // re-located sigma / SIFT sigma, median
};

// `views[v]` as detected (features' index = DirectionObservation::index), with the cone it was
// detected with in `cones[v]`; `refined_cones` and `world_from_cam` per view from a first solve
// (the cones as detected where the balls were not refined); `observations` from
// match_ball_features (index set). Returns the observations to solve again.
std::vector<DirectionObservation> refine_tracks(
    const std::vector<CubeFeatureSet>& views, const std::vector<BallCone>& cones,
    const std::vector<BallCone>& refined_cones, const LensModel& lens, const BallFeatureOptions& features,
    const std::vector<Mat3>& world_from_cam, const std::vector<DirectionObservation>& observations,
    const TrackRefinementOptions& options = {}, TrackRefinementReport* report = nullptr);

}  // namespace rsibr
