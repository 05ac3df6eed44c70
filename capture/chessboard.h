// Chessboard images for intrinsic calibration, rendered through the capture's lens (mrgingham
// detects them; calib/ fits the lens to them).
//
// The board: (corners+1) x (corners+1) squares of side spacing_m, black (reflectance 0.06) and white
// (0.9), with a white border one square wide, on a mid-grey background (0.3); uniformly lit. Board
// frame: origin at the board centre, x right, y down along the squares, z into the board (away from
// a camera that faces it). Inner corner (i, j) (i along x, j along y, 0-based) lies at
// ((i + 1 - (corners+1)/2) spacing, (j + 1 - (corners+1)/2) spacing, 0).
//
// Poses are drawn per board from a seeded stream: distance such that the board spans about half the
// image width, tilts up to 25 degrees about x and y (mrgingham missed some boards tilted up to 35
// about both), a roll up to 15 degrees, and an offset that keeps every corner at least 2 squares'
// image size inside the image (draws that do not are redrawn).
#pragma once

#include "capture/synth_scene.h"
#include "core/lens_model.h"

#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

namespace rsibr {

struct ChessboardShot {
  Mat3 cam_from_board = Mat3::Identity();
  Vec3 board_centre_cam = Vec3::Zero();  // board origin in the camera frame, metres
  std::vector<Vec2> corners;             // true pixel positions, row-major (j outer, i inner)
  cv::Mat reflectance;                   // CV_32FC1, supersampled (n x n jittered) board reflectance
};

ChessboardShot render_chessboard(const LensModel& lens, const RayTable& rays, const SynthChessboards& boards, int index,
                                 std::uint64_t seed, int supersampling);

}  // namespace rsibr
