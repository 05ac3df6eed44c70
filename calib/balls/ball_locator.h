// Ball localisation in one view's linear (HDR) image: sub-pixel outline points -> unprojected rays
// -> robust cone fit (calib/balls/ball_cone.h) -> a second pass that searches across the fitted outline
// in pixels and refits. The image is the merged radiance of the view (hdr/), so one location
// serves all of the view's brackets.
//
// Outline points: along lines across the expected outline (radial from the guess, then normal to
// the fitted outline), the edge is where the log luminance changes most over 2 px; its sub-pixel
// position is where the linear luminance crosses the mean of its levels 1.5 px either side (a
// pixel integrates the radiance over its square, so a straight step edge blurred by the pixel box
// crosses its mid level exactly at the edge). Lines leaving the image (a ball near the edge) or
// without contrast are skipped; outline points on the stand or on features near the outline
// are outliers of the cone fit (RANSAC, Huber loss).
#pragma once

#include "calib/balls/ball_cone.h"
#include "core/lens_model.h"

#include <opencv2/core.hpp>

#include <vector>

namespace rsibr {

struct BallGuess {
  Vec2 centre_px = Vec2::Zero();  // roughly the ball's image centre
  double radius_px = 0;           // roughly its image radius (within ~20%)
};

struct BallLocateOptions {
  int lines = 0;                   // search lines around the outline; 0: about one per 1.5 px of outline (>= 48)
  double search_fraction = 0.25;   // first pass: search radius_px * (1 +- this)
  double refine_px = 3;            // second pass: +- this across the fitted outline
  double min_log_contrast = 0.05;  // edges weaker than this (natural log) are skipped
  // First pass: search a line that leaves the image over its part inside (for a guess that fills a
  // crop, whose lines all reach the frame); false: skip it (a ball the frame cuts: the lines toward
  // the cut would find only the ball's own shading).
  bool clip_lines = false;
  ConeFitOptions fit;
};

struct BallLocation {
  ConeFit fit;                   // the cone (camera frame), inliers, RMS in pixels
  Vec2 centre_px;                // lens.project(axis): the ball centre's pixel
  double radius_px = 0;          // mean distance of the fitted outline from centre_px
  std::vector<Vec2> outline_px;  // the second pass's outline points (inliers and outliers)
  int lines_inside = 0;          // the second pass's search lines inside the image (with or without an edge)
  // Inliers (within `tol_px` of the fitted outline) per search line inside the image: how much of
  // the visible outline shows an edge on the circle (a few edges that happen to lie on a huge
  // circle are all inliers, but of few lines).
  double outline_support(double tol_px) const;
};

// `image` CV_32FC3 (RGB) or CV_32FC1, linear, the lens's size. Throws std::invalid_argument
// ("ball at (x, y): <problem>") when too few outline points are found or no cone fits them.
BallLocation locate_ball(const cv::Mat& image, const LensModel& lens, const BallGuess& guess,
                         const BallLocateOptions& options = {});

// Candidate balls (strongest first, at most `max_count`) from a Hough circle transform of the
// tone-mapped log luminance, with radii in [min_radius_px, max_radius_px]: guesses for locate_ball.
// With per_band > 0 the range is split into bands a factor 2 apart and each band keeps its
// per_band strongest circles (band by band, smallest radii first; max_count then caps the total),
// so large background circles cannot crowd out a ball's.
std::vector<BallGuess> detect_balls(const cv::Mat& image, double min_radius_px, double max_radius_px, int max_count,
                                    int per_band = 0);

}  // namespace rsibr
