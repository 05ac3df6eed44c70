// Which ball is which, in every view, and whether it is a ball at all. The photo set lists the
// balls (kind, diameter when known); a view's image holds them and much else that is round
// (clocks, lamps, plates, wheels, other spheres). Three stages:
//
// 1. Candidates (find_ball_candidates): Hough circles in radius bands a factor 2 apart (one band's
//    strong circles cannot crowd out another's), each located (calib/balls/ball_locator.h) and measured:
//    outline quality (inlier fraction, RMS), appearance (texture: a mirror shows the whole world;
//    a Lambert fit, and the texture it leaves: a diffuse ball's shading is a low-order function of
//    its normal and one sun)
//    and how much of the disc lies inside the frame (a ball cut by the frame edge is flagged).
// 2. One view (assign_balls_in_view): the listed balls matched to candidates by appearance (chrome
//    the most textured, grey the smoothest, glossy between) and size (balls of a rig are at about
//    the same distance from the camera, so their image radii go with their diameters).
// 3. Across views (fit_ball_rig, identify_view_balls), once the rotations are known: the balls sit
//    on one rig, so each ball's centre relative to the chrome ball's, turned into the world frame,
//    is the same vector in every view:
//
//        o_b = R_i (s_b g_bi - c_i),   c_i = a_ci / sin(alpha_ci),   g_bi = a_bi / sin(alpha_bi)
//
//    (in chrome-ball radii; a the cone axes, alpha the half angles, R_i world_from_cam, s_b the
//    ball's radius over the chrome's: the diameters' ratio when both are listed, else estimated).
//    o_b and s_b come from the largest set of views whose candidates agree (every candidate a
//    hypothesis, its support counted), then each view takes its candidate that agrees or, when
//    none does, searches at the place o_b predicts; a view where neither finds the ball reports it
//    missing and leaves it out, never taking a circle that disagrees.
#pragma once

#include "calib/balls/ball_cone.h"
#include "calib/balls/ball_locator.h"
#include "core/lens_model.h"
#include "formats/photo_set.h"
#include "core/vec.h"

#include <opencv2/core.hpp>

#include <optional>
#include <string>
#include <vector>

namespace rsibr {

struct BallCandidate {
  BallLocation loc;
  double inlier_fraction = 0;  // outline points within max(the cone fit's inlier threshold, 0.3% of the radius)
  double outline_support = 0;  // those inliers per search line inside the image (calib/balls/ball_locator.h)
  double texture = 0;          // mean |ln L| change between neighbouring pixels within 0.8 radii
  double rim_texture =
      0;  // fraction of the pixels between 0.5 and 0.9 radii whose ln L changes by > 0.06 to a neighbour
  double mirror_score = 0;  // 98th percentile of |grad log2 L| within 0.9 radii, stops per radius
  double rim_radial =
      0;  // gradients across the rim over those along it, 0.8-0.96 radii, in [-1, 1] (a mirror's compression)
  double diffuse_residual = 0;  // RMS of a Lambert fit (order-2 spherical harmonics and one sun) over 0.9 radii / mean
  double shading_texture = 0;   // mean |ln(L / that fit)| change between neighbouring pixels within 0.8 radii
  double frame_fraction = 1;    // fraction of the fitted outline inside the image
  bool cut = false;             // the disc reaches beyond the frame
};

struct BallSearchOptions {
  double min_radius_px = 0;  // 0: max(4, min(width, height) / 40)
  double max_radius_px = 0;  // 0: min(width, height) / 2
  int per_band = 6;          // Hough circles kept per radius band
  double min_inlier_fraction = 0.6;
  // Inliers per search line inside the image: an edge on the circle along at least half of its
  // visible outline (a few edges of furniture that happen to lie on one large circle are all
  // inliers of it, but of few lines).
  double min_outline_support = 0.5;
  double max_rms_px = 0.8;  // a chrome ball's limb reflects what lies behind it: 0.5 px on low contrast
  double min_frame_fraction = 0.5;
};

// The measures above for a located ball (`image` CV_32FC3 RGB linear, the lens's size).
BallCandidate measure_ball(const cv::Mat& image, const LensModel& lens, const BallLocation& loc);

// The outline's measures of `c` from its location (inlier fraction, outline support, frame
// fraction, cut); the appearance measures are left as they are.
void measure_outline(BallCandidate& c, const LensModel& lens);

// Whether a measured ball passes the outline and frame gates of `options`.
bool acceptable_outline(const BallCandidate& c, const BallSearchOptions& options);

// Candidates passing the gates, one per ball (fits within half a radius of each other merged,
// the one with the most inliers kept; a circle inside a chrome-like candidate's disc dropped: a
// reflection), strongest outline first.
// `frame_circle`, when given, receives the frame-filling circle as located when its outline is
// weak but not absent (support >= 0.3, inliers >= 0.4), whether or not it passed the gates.
std::vector<BallCandidate> find_ball_candidates(const cv::Mat& image, const LensModel& lens,
                                                const BallSearchOptions& options = {},
                                                std::optional<BallLocation>* frame_circle = nullptr);

// What the photo set says about a ball.
struct ListedBall {
  std::string name;
  BallKind kind = BallKind::chrome;
  std::optional<double> diameter_m;
};
std::vector<ListedBall> listed_balls(const PhotoSet& set);

// Appearance: the kind a candidate looks like, from its measures: "chrome", "glossy", "grey"
// compatible (a candidate may fit more than one; none for a ringed disc or a flat textured circle).
bool looks_like(const BallCandidate& c, BallKind kind);

// One view: candidate index per listed ball (-1: none fits), maximising appearance and size
// agreement. Throws nothing; an empty candidate list gives all -1.
std::vector<int> assign_balls_in_view(const std::vector<BallCandidate>& candidates,
                                      const std::vector<ListedBall>& balls);

// One view's candidates and the listed balls assign_balls_in_view matched them to. With one listed
// ball (a crop of it, calib/lens/far_camera.h): the one clean circle that fills the frame is that ball
// whatever its appearance, and circles inside a frame-filling circle are its reflections.
struct ViewCandidates {
  std::vector<BallCandidate> cands;
  std::vector<int> pick;  // per listed ball, candidate index or -1
};
ViewCandidates view_candidates(const cv::Mat& image, const LensModel& lens, const std::vector<ListedBall>& balls,
                               const BallSearchOptions& search = {});

// Appearance alone can miss a chrome ball: in a soft, low-contrast room its rim is smooth and it
// passes no chrome test (it still shows a mirror's range, unlike a diffuse ball). The distance between
// the chrome ball's centre and another listed ball's does not depend on the camera's rotation, so
// the views where both were matched give it before any solve: their median d, when at least two
// views agree with it (within 1 + 0.04 d chrome radii). A view where the chrome ball was missed but
// the other ball was matched takes the one remaining candidate with an acceptable outline that looks
// glossy and not grey and lies at distance d from it (within 1 + 0.04 x the mean camera distance,
// chrome radii); two such candidates or none: still missed. Needs both diameters listed (the scale
// between the balls). Per view (nullopt: not searched): the rescued candidate (-1: none) and a note.
struct ChromeRescue {
  int candidate = -1;
  std::string note;
};
std::vector<ChromeRescue> rescue_chrome_balls(const std::vector<std::optional<ViewCandidates>>& views,
                                              const std::vector<ListedBall>& balls,
                                              const BallSearchOptions& search = {});

// One view's balls as the cross-view stage sees them.
struct ViewBalls {
  std::string name;
  std::vector<BallCandidate> candidates;
  std::optional<BallCone> chrome;  // the anchor (the pose's refined chrome ball, or the view's chrome candidate)
  Mat3 world_from_cam = Mat3::Identity();
  std::string anchor_note;  // how the anchor was found, when not by the orientation (the report's note)
};

// The rig: per listed ball its centre relative to the chrome ball's (world, chrome-ball radii) and
// its radius over the chrome's; unknown when too few views agree.
struct RigMember {
  bool known = false;
  Vec3 offset = Vec3::Zero();
  double scale = 1;          // radius / chrome radius
  bool scale_given = false;  // from the listed diameters (else estimated)
  int support = 0;           // views agreeing
  double rms = 0;            // RMS disagreement of the supporting views, chrome radii
};

struct RigOptions {
  double tolerance = 1.0;  // agreement: within tolerance + relative * (|c| + |s g|) / 2 chrome radii
  double relative_tolerance = 0.04;
  int min_support = 2;  // views that must agree (fewer views: all of them)
};

// Chrome balls (kind chrome) are the anchors (offset 0, scale 1 for the first; others fitted like
// the rest). Each view's candidates are claimed by one ball at most.
std::vector<RigMember> fit_ball_rig(const std::vector<ViewBalls>& views, const std::vector<ListedBall>& balls,
                                    const RigOptions& options = {});

// A view whose chrome ball no appearance test accepts (backlit by a low sun, it shows a smooth sky
// and a thin bright rim) and whose pose came without it: the rig, fitted on the other views, places
// it from the balls that are found. The chrome cone, the ball it was placed from, and the
// distance between the placed and the found centre (chrome radii). None when the view has an
// anchor, no member is known or no candidate agrees.
struct AnchorFromRig {
  BallCone chrome;
  std::string placed_from;
  double disagreement = 0;
};
std::optional<AnchorFromRig> anchor_from_rig(const ViewBalls& view, const std::vector<RigMember>& rig,
                                             const std::vector<ListedBall>& balls, const RigOptions& options = {});

// One ball in one view, as identification decided.
struct BallFinding {
  std::string status = "missing";     // "found", "found at the predicted place", "given", "missing"
  std::optional<BallCandidate> ball;  // when found
  std::string note;                   // what was checked (for the report), or why it is missing
  double disagreement = -1;           // distance from the rig's prediction, chrome radii (-1: not checked)
  std::optional<Vec2> predicted_px;   // where the rig put it
  double predicted_radius_px = 0;
  bool found() const { return ball.has_value(); }
};

// Per listed ball of one view. `image` is searched at the predicted place of a ball no candidate
// agrees with. Without an anchor (no chrome in the view) or a known rig member, a ball is taken
// from the view's own assignment only when `trust_view` (single-view shoots); otherwise it is missing.
std::vector<BallFinding> identify_view_balls(const ViewBalls& view, const std::vector<RigMember>& rig,
                                             const std::vector<ListedBall>& balls, const cv::Mat& image,
                                             const LensModel& lens, const RigOptions& rig_options = {},
                                             const BallSearchOptions& search = {}, bool trust_view = false);

// Views whose balls disagree with the rig. A chrome outline found on a reflection's edge inside the
// rim (a bright limb against a bright background) moves the ball's centre a few pixels, and the
// orientation solve turns the view by degrees to match its features, with a small sigma: its other
// balls then lie far from where the rig puts them. Per view its largest disagreement (chrome radii;
// < 0: none checked) -> per view whether it is suspect: farther than max(radii, median_factor x the
// median of the checked views), when 3 or more were checked. Why these numbers: docs/tradeoffs.md,
// "Measured choices in the code".
struct RigSuspectOptions {
  double radii = 0.25;
  double median_factor = 4;
};
struct RigSuspects {
  std::vector<char> suspect;
  double median = -1;  // of the checked views (-1: fewer than 3)
  double limit = -1;
};
RigSuspects rig_suspects(const std::vector<double>& disagreement, const RigSuspectOptions& options = {});

// The cone of a ball at `offset` (world, chrome radii) and radius `scale` from the chrome cone of a view.
BallCone predicted_cone(const BallCone& chrome, const Mat3& world_from_cam, const Vec3& offset, double scale);

// The ball's cone fitted again without its outline points on or inside `others` (balls in front of
// it, whose edges are not its own): the located ball unchanged when no point goes or too few stay.
BallLocation refit_outline_excluding(const BallLocation& ball, const LensModel& lens,
                                     const std::vector<BallLocation>& others);

// A ball given by hand: located at the guess (calib/balls/ball_locator.h) within 6%, 12% and 25% of its
// radius, the outline that shows most of itself kept, and measured. Throws std::invalid_argument
// when no band finds an outline.
BallCandidate given_ball(const cv::Mat& image, const LensModel& lens, const BallGuess& guess);

// Two fits of one circle: centres within half the smaller radius and radii within 30% of it
// (concentric circles of different radii, a ball in front of a ringed disc, are different circles).
bool same_circle(const BallLocation& a, const BallLocation& b);

}  // namespace rsibr
