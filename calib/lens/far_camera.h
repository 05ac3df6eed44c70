// Photos cropped to the ball, the usual form of chrome-ball data in the wild: each photo is a
// window of an unknown size and place in an unknown frame, so neither the EXIF focal length (it
// belongs to the uncropped frame) nor the principal point says anything about the camera, and the
// views of one shoot differ in size by a few pixels or by hundreds. What a crop does say is that
// the camera was far from the ball compared with its size: the ball's image is nearly a circle
// and its reflection nearly the orthographic mirror-ball map. The far-camera model is that limit:
// one pinhole for every view on a canvas of the largest view's size, principal point at the
// canvas centre, and a focal length so long that the ball subtends a half-angle of
//   alpha = asin(r / f) < asin(1 / (2 k)) = 0.29 degrees,   f = k * max(W, H), k = 100,
// for any ball inside the frame (r <= max(W, H) / 2). Where a view was placed on the canvas does
// not matter in this limit (a shift of the principal point by the canvas size turns the view's
// rays by under 1 / k rad). The model's error is the true perspective it leaves out, about
// asin(R / D) across the ball (DESIGN: Perspective); no crop tells D, so none can do better.
//
// A view is a crop of the ball when the ball's diameter is at least 60% of the frame's shorter
// side (a ball that large in an uncropped photo means a lens a few ball radii away: macro work,
// not a light probe shoot).
#pragma once

#include "calib/view_image.h"
#include "core/lens_model.h"

#include <vector>

namespace rsibr {

inline constexpr double kFarCameraFocalPerSide = 100;  // k above
inline constexpr double kCropFillFraction = 0.6;       // diameter / shorter side of a crop

// Whether a ball of this radius fills a width x height frame as a crop does.
bool fills_frame(double radius_px, int width, int height);

// The far-camera pinhole for views of these sizes (>= 1): canvas = the largest width and height.
LensModel far_camera_lens(const std::vector<std::pair<int, int>>& sizes);

// Whether `lens` is such a far camera (a pinhole whose focal length is k times its canvas's longer
// side, as far_camera_lens makes it; a written and re-read model to 1e-6).
bool is_far_camera(const LensModel& lens);

// `view` placed at the canvas's top-left corner when the lens's canvas is larger: the radiance
// continued by replicating its border (no edge where the photo ends, for the ball finder) and the
// added pixels flagged kOutside (hdr/merge.h: not seen, for extraction and features). Returns the
// view unchanged when it has the lens's size. Throws std::invalid_argument("<name>: <problem>")
// when the view is larger than the lens in either direction.
ViewImage on_lens_canvas(ViewImage view, const LensModel& lens, const std::string& name);

}  // namespace rsibr
