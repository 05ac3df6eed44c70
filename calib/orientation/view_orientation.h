// Every view's orientation from its image of the chrome ball: the ball found in each view (the
// candidates and the listed balls matched by appearance and size, calib/balls/ball_identification.h), SIFT
// features of the world it reflects, detected on cube faces (calib/orientation/ball_cube_features.h; or in the
// image itself, calib/orientation/ball_features.h) as reflected directions, matched across views and
// solved in one Ceres problem (calib/orientation/orientation_solve.h). The result is a pose file's content
// (calib/orientation/pose_file.h).
//
// Gauge (the world frame, which the images cannot fix):
//   first-view  world = the first view's camera frame (world_from_cam of view 0 = identity).
//   up          options.up is the world's up (+Y) expressed in the first camera's frame (unit after
//               normalising; e.g. (0, -1, 0) for a camera levelled on a tripod, whose y axis points
//               down); the world's +Z is the first camera's forward axis made horizontal (or its
//               -y axis when it looks straight up or down), X = Y x Z.
//   estimated   estimate_up: the first-view solve, then up estimated from the cameras' x axes
//               (calib/orientation/world_up.h) and used as `up` (gauge "estimated-up").
// A view without a chrome ball found is left out (reported) while two or more remain.
#pragma once

#include "calib/orientation/ball_cube_features.h"
#include "calib/orientation/ball_features.h"
#include "calib/balls/ball_identification.h"
#include "calib/balls/ball_locator.h"
#include "calib/orientation/orientation_solve.h"
#include "calib/orientation/point_pairs.h"
#include "calib/orientation/pose_file.h"
#include "calib/orientation/rotation_search.h"
#include "calib/orientation/stand_line.h"
#include "calib/orientation/track_refinement.h"
#include "calib/orientation/view_agreement.h"
#include "calib/view_image.h"
#include "calib/orientation/world_up.h"
#include "core/lens_model.h"

#include <optional>
#include <string>
#include <vector>

namespace rsibr {

// Where features are detected: `cube` resamples the world reflected in the ball onto gnomonic cube
// faces first (calib/orientation/ball_cube_features.h; matches across wide baselines, and its tracks are
// re-located by patch alignment, calib/orientation/track_refinement.h), `image` runs SIFT on the ball's image
// directly (calib/orientation/ball_features.h; views < ~20-30 degrees apart only). Why `cube` is the default:
// measured in docs/tradeoffs.md, "Orientation".
enum class FeatureDomain { cube, image };

struct ViewOrientationOptions {
  std::optional<Vec3> up;    // camera frame of the first view; none: the first-view gauge
  bool estimate_up = false;  // without `up`: estimated from the views (gauge "estimated-up")
  WorldUpOptions up_options;
  bool stand_lines =
      true;  // with estimate_up: the stand under each chrome ball as a vertical line (calib/orientation/stand_line.h)
  StandLineOptions stand;
  std::vector<BallGuess> balls;                        // per view, or empty: detected
  std::vector<std::optional<BallGuess>> given_chrome;  // per view or empty: a given chrome ball (--ball)
  std::vector<ListedBall> listed;                      // the photo set's balls (empty: one chrome ball)
  // Per view or empty: the view's candidates and picks as the balls step found them
  // (calib/balls/shoot_balls.h, through this lens; a rescued or given chrome ball is its pick), so
  // nothing is searched here; empty: each view searched, then the chrome rescue.
  std::vector<ViewCandidates> candidates;
  BallSearchOptions search;  // min/max radius 0: min(width, height) / 40 and / 2
  // Known rotations (a pose file without balls), per view: the features refine only the balls.
  std::vector<Mat3> known_world_from_cam;
  // Denser than BallFeatureOptions' defaults: weaker SIFT features (contrast 0.01) and out to 0.95 of
  // the ball's angular radius. The rim's features are what separates a ball-centre error from a
  // rotation. Why these settings: measured in docs/tradeoffs.md, "Measured choices in the code".
  BallFeatureOptions features = {800, 0.3, 0.95, 25, 0.01};
  FeatureDomain domain = FeatureDomain::cube;
  CubeFeatureOptions cube;
  // Ball centres refined jointly with the orientations (OrientationOptions::balls), with a prior
  // std dev of the ball centre of max(outline RMS, ball_prior_px) pixels.
  // The half angle too, with a prior std dev of ball_radius_prior_px pixels of image radius (0: held
  // at the outline's): a chrome ball's outline is found inside its limb (the limb reflects what lies
  // just behind the ball, so the steepest edge is further in), 0.3-2 px on a 120 px ball.
  bool refine_balls = true;
  double ball_prior_px = 0.25;
  double ball_radius_prior_px = 2;
  // Cube domain: after a first solve, every track re-located by patch alignment against its
  // sharpest observation (calib/orientation/track_refinement.h), then solved again. Why on by default: measured
  // in docs/tradeoffs.md, "Orientation" and "Measured choices in the code".
  bool refine_tracks = true;
  TrackRefinementOptions tracks;
  // With estimate_up and other listed balls: each view's other balls checked against the rig fitted
  // on all views; a suspect view (calib/balls/ball_identification.h, rig_suspects) is left out of the
  // world-up estimate and noted.
  bool rig_check = true;
  RigSuspectOptions rig_suspect;
  OrientationOptions solve;  // its first_world_from_cam is set from the gauge
  // When the features matched over the whole sphere leave a view unplaced: every pair's rotation
  // searched by correlating the balls' panoramas (calib/orientation/rotation_search.h); pairs scoring at least
  // min_search_score form a spanning tree (best scores first) whose chained rotations gate a second
  // matching (MatchGuess). Real views far apart share too few features that pass an unguided
  // ratio test over the whole sphere. Only then, so a shoot the features orient is not changed.
  bool search_rotations = true;
  PanoramaOptions panorama;
  RotationSearchOptions rotation_search;
  double min_search_score = 0.5;
  double gate_deg = 4;  // the search's error plus a room's parallax a few metres away
  // A view's matched pairs must agree within consensus_deg beyond chance (a pair inside the gate
  // agrees by chance with up to (consensus_deg / gate_deg)^2, one matched over the whole sphere
  // with the share of the sphere a consensus cap covers): the Poisson tail of its agreeing count
  // at most max_chance; otherwise it is left out.
  // Points picked by hand (calib/orientation/point_pairs.h): one more track each; a view they tie in is not
  // tested against chance. match_features false: the picked points alone.
  PointPairs points;
  bool match_features = true;
  double consensus_deg = 2;
  double max_chance = 1e-3;
};

// One pair of oriented views, for reports: the rotation search, the matches and, after the solve,
// the inliers.
struct PairOrientation {
  std::string a, b;
  int features_a = 0, features_b = 0;
  int matched = 0;  // mutual matches (gated: under the search's rotations)
  bool gated = false;
  int shared_tracks = 0;  // tracks observed by both
  int inliers = 0;        // of those: both observations within the solve's inlier_deg of each other
  // What chance would give under the search's gate: shared_tracks (inlier_deg / gate_deg)^2 (0 ungated).
  double chance_inliers = 0;
  double search_score = -1, search_runner_up = -1, search_overlap = 0;
  double search_angle_deg = 0;  // the searched relative rotation's angle
  // Angle between the solved relative rotation and the searched one (-1 without a search).
  double solved_vs_search_deg = -1;
  ViewAgreement agreement;  // at the solved rotations (calib/orientation/view_agreement.h); samples 0 if unsolved
  // The shared tracks' features: their pixels in a and in b, and whether they are inliers.
  std::vector<std::pair<Vec2, Vec2>> matches_px;
  std::vector<char> match_inlier;
};

// What orient_views saw, for reports (--json).
struct ViewOrientationReport {
  std::vector<std::string> names;       // the views oriented (the rest were left out)
  std::vector<std::string> left_out;    // "<view>: <why>"
  std::vector<std::string> notes;       // "<view>: <what was decided>" (a chrome ball placed from another ball)
  std::vector<BallLocation> balls;      // per view oriented (centre_px and the cone's axis refined when refine_balls)
  std::vector<BallCandidate> measured;  // per view oriented: the chrome ball as found (before refinement)
  std::optional<WorldUp> world_up;      // estimated up (in the first view's camera frame)
  std::vector<int> features;            // per view: features in the ball
  int tracks = 0, observations = 0, inliers = 0;
  double rms_sigmas = 0;
  TrackRefinementReport track_refinement;  // zero when tracks were not re-located
  // Per view oriented: the largest distance (chrome radii) of its other listed balls from where the
  // rig fitted on all views puts them (calib/balls/ball_identification.h), -1 where none was checked; and
  // whether that makes it a view left out of the world-up estimate (ViewOrientationOptions::rig_check).
  std::vector<double> rig_disagreement;
  std::vector<char> rig_suspect;
  std::vector<PairOrientation> pairs;  // every pair of views oriented
};

// The world_from_cam of the first view for the gauge (identity without `up`). Throws
// std::invalid_argument for a zero or non-finite up.
Mat3 gauge_world_from_first_cam(const std::optional<Vec3>& up);

// Levels a pose set: world up estimated from its rotations and `lines` (world frame of the set;
// calib/orientation/world_up.h), and the world turned
// so that it is +Y and the first view's forward axis, made horizontal, is +Z (the "up" gauge with
// the estimated up); gauge becomes "estimated-up". Returns the estimate, up in the first view's
// camera frame. Throws std::invalid_argument for an empty set.
// `in_estimate`: per view, whether its rotation joins the estimate (empty: every view); every view
// is levelled, and the returned roll_deg is per view of the set (those left out included).
WorldUp level_pose_set(PoseSet& poses, const WorldUpOptions& options = {}, const std::vector<VerticalLine>& lines = {},
                       const std::vector<char>& in_estimate = {});

// The cone to extract a located ball with: the pose's refined chrome ball (ViewPose::ball) when it is
// the same ball (its centre's pixel within half the located radius of the located centre), else the
// located outline's.
BallCone extraction_cone(const BallLocation& located, const ViewPose& pose, const LensModel& lens);

// The chrome ball of one view: candidates (calib/balls/ball_identification.h) matched to the listed balls;
// nullopt when none looks like a chrome ball. `overlapping`, when given, gets the ball-sized
// candidates whose discs overlap it (their pixels give no features: one may be in front).
std::optional<BallCandidate> find_chrome_ball(const cv::Mat& image, const LensModel& lens,
                                              const std::vector<ListedBall>& listed, const BallSearchOptions& search,
                                              std::vector<BallLocation>* overlapping = nullptr);

// `names` and `views` parallel, >= 2 views, all of the lens's size. Throws std::invalid_argument
// with a message naming the view ("<name>: no ball found", "orient: view '<name>' shares 0
// feature(s) with the other views; ...", "orient: 1 view(s), need at least 2") or
// std::runtime_error when the solve fails.
PoseSet orient_views(const std::vector<std::string>& names, const std::vector<ViewImage>& views, const LensModel& lens,
                     const ViewOrientationOptions& options = {}, ViewOrientationReport* report = nullptr);

}  // namespace rsibr
