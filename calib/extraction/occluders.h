// What hides the world in a chrome ball's reflection, by geometry: the other balls, the stands
// under the balls and the photographer behind the camera. A chrome map's texel shows the world
// along the reflected ray from its surface point; a texel whose ray meets an occluder shows the
// occluder, not the environment, and gets confidence 0 (calib/extraction/sphere_map_extraction.h).
//
// Units and frame: the camera frame of the view (x right, y down, z forward), lengths in radii of
// the chrome ball (its centre at C = axis / sin(alpha)), as the extraction's geometry is.
//   sphere     a ball at `centre`, radius `radius` (inflated by the margin)
//   cylinder   a vertical pole or the photographer: points base + t * axis, t in [0, length],
//              within `radius` of that segment (a capsule)
#pragma once

#include "calib/balls/ball_cone.h"
#include "core/vec.h"

#include <optional>
#include <string>
#include <vector>

namespace rsibr {

struct Occluder {
  enum Kind { sphere, capsule } kind = sphere;
  Vec3 centre = Vec3::Zero();  // sphere centre, or the capsule segment's start
  Vec3 axis = Vec3(0, 1, 0);   // capsule: unit direction of the segment
  double length = 0;           // capsule
  double radius = 1;
  std::string what;  // "ball grey", "stand under chrome", "photographer"
};

// Whether the ray o + t d (t in (0, t_max), d unit) meets the occluder.
bool ray_hits(const Occluder& occ, const Vec3& o, const Vec3& d, double t_max = 1e6);

struct OccluderOptions {
  double ball_margin = 1.15;  // other balls' radii times this
  double stand_radius =
      0.5;  // a stand's radius, in radii of the ball it holds (a light stand ~ 1/4 of a 10 cm ball's diameter)
  double stand_length_m = 2.0;  // how far down a stand is masked
  bool photographer = true;
  // The photographer, as a capsule about the vertical through a point `behind_m` behind the camera,
  // from `above_m` above the camera down `below_m`, radius `radius_m` (shoulders and a margin).
  double photographer_radius_m = 0.35, photographer_above_m = 0.3, photographer_below_m = 1.8,
         photographer_behind_m = 0.15;
};

// A ball of the view besides the chrome ball: its cone and its radius over the chrome's.
struct OtherBall {
  std::string name;
  BallCone cone;
  double scale = 1;
};

// The occluders of a chrome ball's view: the other balls, a stand under every ball (world down
// `down_cam`, camera frame; none: no stands or photographer), the photographer. `chrome_radius_m`
// sets the scale of the metric sizes (the listed diameter / 2, or a 5 cm assumption when unknown).
std::vector<Occluder> chrome_occluders(const BallCone& chrome, const std::vector<OtherBall>& others,
                                       const std::optional<Vec3>& down_cam, double chrome_radius_m,
                                       const OccluderOptions& options = {});

}  // namespace rsibr
