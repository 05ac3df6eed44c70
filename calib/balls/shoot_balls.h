// Every listed ball of every view of a shoot, found once (the `balls` step of rsibr process): each
// view's candidates (calib/balls/ball_identification.h, view_candidates), the listed balls matched
// in the view by appearance and size, a chrome ball missed by appearance rescued by its distance
// from another ball (rescue_chrome_balls), and the balls given by hand (--ball) located at their
// guesses. Later steps read the result (calib/balls/balls_file.h) instead of searching again:
// the lens step measures the focal length from the outlines, orient takes the chrome balls, and
// extract fits the rig from the candidates.
//
// The candidates are located through the lens the step was given (the calibrate step's; a pinhole
// of the view's diagonal for a view of another size, a crop). A later step whose lens differs (a
// refined focal length, the far camera of crops) refits each candidate's cone to the same outline
// pixels (candidates_for_lens): the outline is what the image shows, the cone what a lens makes of
// it. Pixels are the merged view's own (a view put on a larger canvas keeps them: the canvas
// extends it to the right and below, calib/lens/far_camera.h).
#pragma once

#include "calib/balls/ball_identification.h"
#include "calib/view_image.h"
#include "core/lens_model.h"

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace rsibr {

// One listed ball in one view.
struct FoundBall {
  // "found" (the view's candidates, by appearance and size), "rescued" (a chrome ball, by its
  // distance from another ball), "given" (--ball), "missing".
  std::string status = "missing";
  int candidate = -1;  // index into the view's candidates (-1: missing)
  std::string note;    // how a rescued ball was found
};

struct FoundView {
  std::string name;
  int width = 0, height = 0;  // the merged view's size (pixels)
  // The lens the candidates were located through.
  LensModel lens = LensModel::pinhole(1, 1, 1);
  std::vector<BallCandidate> candidates;  // outline pixels, cones, measures
  std::vector<FoundBall> balls;           // per listed ball
};

struct ShootBalls {
  std::vector<ListedBall> listed;  // the photo set's balls (none listed: one chrome ball, "chrome")
  std::vector<FoundView> views;    // in the photo set's order
  const FoundView* find(const std::string& view) const;
};

struct ShootBallsInput {
  std::vector<std::string> views;
  std::function<ViewImage(std::size_t view)> read_view;  // a view's merged image, its own size
  LensModel lens = LensModel::pinhole(1, 1, 1);          // the calibrate step's lens
  std::vector<ListedBall> listed;                        // the photo set's balls
  // Per view (empty: none given), per listed ball: the ball given by hand.
  std::vector<std::vector<std::optional<BallGuess>>> given;
  // Per view: the bracket its registration left furthest off (for a ghost's error), or "".
  std::vector<std::string> suspect_bracket;
  BallSearchOptions search;
  // Called once per view with its image and candidates (for the candidates picture), one call at a
  // time; may be empty.
  std::function<void(std::size_t view, const cv::Mat& radiance, const ViewCandidates& found)> seen;
};

// A view's main ball (the lens step's evidence): its first listed chrome ball found, else its
// largest ball found; -1 when none is found.
int main_ball(const FoundView& view, const std::vector<ListedBall>& listed);

// The views are searched in parallel, as many at once as there are threads (each holds its image);
// `read_view` must be safe to call from several threads, and `seen` is called under a lock, in no
// particular order. The result does not depend on the threads. Throws std::invalid_argument when a
// given ball is not found at its guess ("balls: view VIEW: ..."), and when
// more than 2% of a view's main ball's pixels are flagged as ghosts by the merge (hdr/merge.h kGhost:
// a bracket taken from another place, or cropped elsewhere), whose outline would be found wrong
// (a well registered shoot has under 0.1%).
ShootBalls find_shoot_balls(const ShootBallsInput& in);

// The view's candidates as `lens` sees them: unchanged when it is the lens they were located
// through, else each cone fitted again to the same outline pixels (inlier fraction, outline support
// and frame fraction with it; the appearance measures kept). pick: per listed ball, candidate or -1.
ViewCandidates candidates_for_lens(const FoundView& view, const LensModel& lens);

// A candidate's cone fitted again through another lens to its outline pixels.
BallCandidate candidate_with_lens(const BallCandidate& c, const LensModel& lens);

}  // namespace rsibr
