// The `extract` step of rsibr process (pipeline/process_pipeline.h), after orient: every listed
// ball of every posed view identified and checked across views (calib/balls/ball_identification.h: the
// rig of balls fitted from every view's candidates, as the balls step found them, each view's balls
// decided against it), and
// extracted into the world frame (calib/extraction/sphere_map_extraction.h). A ball not found in a view is
// left out of that ball's maps and reported. Chrome maps mask the other balls, the stands and the
// photographer by geometry (calib/extraction/occluders.h); a chrome view whose other balls disagree with the
// rig stays out of the probe. Grey maps get the light the photographer takes from them restored
// (calib/extraction/occluded_light.h, from the chrome maps' probe with its clipped light recovered), and what
// one view alone sees differently masked (calib/extraction/lambert_consensus.h). Nothing is written here:
// the caller writes the map sets and the masks.
#pragma once

#include "calib/balls/shoot_balls.h"
#include "calib/orientation/pose_file.h"
#include "calib/view_image.h"
#include "formats/atomic_folder.h"
#include "core/lens_model.h"
#include "formats/map_set.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace rsibr {

struct ExtractStep {
  const LensModel* lens = nullptr;  // the lens step's lens
  PoseSet poses;                    // the orient step's poses (a view without one is left out)
  std::vector<std::string> views;   // the photo set's views, in order
  // A view's merged image, on the lens's canvas (read twice: the candidates, then the extraction).
  std::function<ViewImage(const std::string& view)> read_view;
  // The balls step's findings (calib/balls/shoot_balls.h): the listed balls and every view's
  // candidates, refitted here through `lens`; a ball given by hand (status "given") is taken as it is.
  ShootBalls found;
  int map_size = 0;     // texels a side; 0: from the balls' pixel radii (pipeline/default_sizes.h)
  int probe_width = 0;  // of the probe the grey balls' occluded light is read from; 0: from the chrome map's size
  bool occluder_light = true;   // restore the light the photographer takes from the grey balls
  std::string chrome_fresnel;   // the chrome ball's Fresnel spec (YAML text)
  bool recover_sources = true;  // that probe with the light clipped in every view recovered
  double grey_albedo = 0.18;
  std::uint64_t seed = 0;
  bool progress = false;  // a progress bar on stderr
};

struct ExtractedMaps {
  std::vector<MapSet> sets;  // per listed ball (every one with at least one view)
  FolderContents masks;      // each map's mask picture: <view>.png (chrome), <view>-<ball>.png (others)
  nlohmann::json summary;    // per view and ball what was found and done; sizes; the rig
};

// Throws std::invalid_argument for a step without lens or poses, std::runtime_error when a listed
// ball is found in no view (naming it, and --ball to give it).
ExtractedMaps run_extract_step(const ExtractStep& s);

}  // namespace rsibr
