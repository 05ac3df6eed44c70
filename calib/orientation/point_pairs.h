// Corresponding points picked by hand, the fallback when a shoot's features do not tie its views
// together: each point is one thing in the world (a window corner, a lamp) at the pixel where it
// shows in the chrome ball of two or more views. The orientation solve (calib/orientation/view_orientation.h)
// takes each as one more track, its directions reflected off the view's ball like a feature's.
//
// File (YAML; pixels of the merged view, hdr/VIEW.exr, which are the photos' own pixels; (0, 0)
// the centre of the top-left pixel):
//   rsibr_points: 1
//   sigma_px: 2            # optional: how well a point was placed, pixels (default 2)
//   points:
//     - {name: skylight corner, angle1: [512.3, 200.1], angle2: [100.2, 340.0]}
//     - {angle1: [300, 410], angle2: [622.5, 388]}    # name optional
#pragma once

#include "core/vec.h"

#include <filesystem>
#include <string>
#include <vector>

namespace rsibr {

struct PickedPoint {
  std::string name;                                // "" when not given
  std::vector<std::pair<std::string, Vec2>> seen;  // (view, pixel), two or more views
  std::string where;                               // "FILE: points[k]" for messages
};

struct PointPairs {
  std::vector<PickedPoint> points;
  double sigma_px = 2;
};

// Throws std::invalid_argument("<file>: <key path>: <problem>") for a malformed file, a point seen
// in fewer than two views or twice in one view, or a non-finite pixel.
PointPairs read_point_pairs(const std::filesystem::path& file);

}  // namespace rsibr
