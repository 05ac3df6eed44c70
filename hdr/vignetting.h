// Vignetting: a lens passes less light toward the frame's edges, so a pixel records v(p) L instead
// of the scene's L. The model is the radial polynomial of lens databases (lensfun's "pa"):
//
//   v(p) = 1 + k1 r^2 + k2 r^4 + k3 r^6,   r = |p - c| / r_corner
//
// c the principal point (pixels, integers at pixel centres), r_corner the distance from c to the
// farthest image corner (r = 1 there; lensfun normalises to half the diagonal, the same when c is
// the image centre). The merge divides it out: radiance / v, variance / v^2.
//
// Estimate from the chessboard images (photographed with the same camera): every white square
// between four detected inner corners is sampled on a 5 x 5 grid in its middle (away from its
// edges), its codes made linear by the camera's response and summed over R, G, B; the square's
// value is the median. Each board has its own level and a linear light gradient across it (real
// boards are not evenly lit), so
//
//   ln y_s = beta_b + a_b x_s + b_b y_s + ln v(r_s; k)        (x, y = (p - c) / r_corner)
//
// and only the curvature of v within each board, together with the boards' different places in
// the frame, fixes k (a linear gradient is not vignetting). Gauss-Newton with Huber weights
// (scale 1.4826 MAD). The degree (1, 2 or 3 terms) is chosen by leave-one-board-out error: each
// board's squares predicted from the others' v with only its own level and gradient fitted (a
// higher degree must lower that error by 2% to be chosen). Squares near clipping (any channel
// >= 97% of the top code) or near black (< 2%) are skipped.
#pragma once

#include "core/vec.h"
#include "hdr/merge.h"
#include "hdr/response_curve.h"

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace rsibr {

struct Vignetting {
  Vec2 centre = Vec2::Zero();  // principal point, pixels
  double r_corner = 1;         // pixels
  std::array<double, 3> k{0, 0, 0};
  std::string source = "none";  // how it was obtained ("none", "chessboards", "given: <file>")

  // v at pixel (x, y), clamped to >= 0.05 (a polynomial extrapolated beyond its data can dive).
  double at(double x, double y) const;
  // -log2 v at r = 1: how many stops the farthest corner is darkened.
  double corner_stops() const;
  bool is_identity() const { return k[0] == 0 && k[1] == 0 && k[2] == 0; }

  // No vignetting, centred on c for an image of the given size.
  static Vignetting none(int width, int height, const Vec2& c);
};

// r_corner of an image of this size for principal point c.
double vignetting_corner_radius(int width, int height, const Vec2& c);

// A chessboard image for the estimate: its codes (CV_16UC3 RGB of the response curve's bit depth;
// 8-bit boards against a 16-bit curve are scaled by 257) and its inner corners, gridn x gridn,
// row-major (mrgingham's order, calib/lens/intrinsics.h find_chessboard).
struct VignettingBoard {
  std::string name;
  cv::Mat codes;
  std::vector<Vec2> corners;
  int gridn = 0;
};

struct VignettingEstimate {
  Vignetting model;                             // identity when there is no estimate (fewer than 3 boards)
  int degree = 0;                               // polynomial terms used (0: no estimate)
  int boards = 0, squares = 0;                  // used
  double rms = 0;                               // RMS of ln y residuals after the fit (relative error of a square)
  double corner_sigma_stops = 0;                // std dev of corner_stops (the fit's covariance)
  double max_r = 0;                             // the farthest square's r (beyond it the polynomial extrapolates)
  std::array<double, 3> held_out_rms{0, 0, 0};  // per degree 1..3, leave-one-board-out
  std::string note;                             // why there is no estimate, when there is none
};

// Throws std::invalid_argument for a board whose codes are not CV_16UC3 or whose corners are not
// gridn^2; boards whose squares cannot be measured are skipped (counted in `boards` only if used).
VignettingEstimate estimate_vignetting(const std::vector<VignettingBoard>& boards, const ResponseCurve& curve,
                                       const Vec2& centre, int width, int height);

// A board image read for the estimate (PNG/JPEG/TIFF, grey or colour, 8 or 16 bit) as CV_16UC3 RGB.
// Throws std::runtime_error("<file>: ...") when it cannot be read.
cv::Mat read_board_codes(const std::filesystem::path& file);

// radiance /= v and variance /= v^2, per pixel (the image's size).
void divide_vignetting(MergedImage& image, const Vignetting& v);

// {"model": "pa", "centre_px", "r_corner_px", "k", "corner_stops", "source"}.
nlohmann::json vignetting_json(const Vignetting& v);
// Reads what vignetting_json writes (extra keys ignored); throws std::invalid_argument("<what>: ...").
Vignetting vignetting_from_json(const nlohmann::json& j, const std::string& what);

}  // namespace rsibr
