// The picture a user picks a ball from: a view's image (tone-mapped at its middle tone, display
// encoded) with every candidate circle drawn and numbered in the order given, the chosen ones (if
// any) in green, the others in orange, scaled so its long side is at most `max_side` pixels. The
// numbers are the ones `rsibr balls` lists, so a user can copy a circle into --ball VIEW:BALL=X,Y,R.
// BGR, 8-bit, ready for PNG.
#pragma once

#include "calib/balls/ball_identification.h"

#include <opencv2/core.hpp>

#include <filesystem>
#include <vector>

namespace rsibr {

// `image` CV_32FC3 RGB linear; `chosen` holds indices into `candidates`.
cv::Mat ball_candidates_picture(const cv::Mat& image, const std::vector<BallCandidate>& candidates,
                                const std::vector<int>& chosen = {}, int max_side = 1600);

// A view's candidates and picks (view_candidates) drawn as above and written atomically as a PNG.
// Throws std::runtime_error("<png>: ...") when it cannot be written.
void write_ball_candidates_picture(const std::filesystem::path& png, const cv::Mat& image, const ViewCandidates& vc);

}  // namespace rsibr
