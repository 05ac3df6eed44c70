// A photo set's views merged the way rsibr hdr and rsibr process both do it: the camera response
// and the noise model recovered once, from every view (loaded one at a time, aligned when asked;
// bracket_statistics.h), then each view's brackets loaded again and merged (merge_view_radiance:
// the one function both call, so the verb and the step write the same radiance). `align`: how brackets
// are registered first (hdr/alignment.h; files of different sizes are accepted unless off).
#pragma once

#include "formats/photo_set.h"
#include "hdr/alignment.h"
#include "hdr/bracket_set.h"
#include "hdr/merge.h"
#include "hdr/noise_model.h"
#include "hdr/response_recovery.h"
#include "hdr/vignetting.h"

#include <opencv2/core.hpp>

#include <optional>
#include <string>
#include <vector>

namespace rsibr {

struct PhotoSetResponse {
  ResponseRecovery recovery;           // model "identity": the identity curve, no candidates
  NoiseModel noise;                    // estimated from every view with that curve
  std::vector<const PhotoView*> from;  // the views with at least two brackets (what it was recovered from)
};

// `views` non-empty. options.model "identity" skips the fit (linear input). `curve`: reuse this
// response instead of recovering one (the noise is still estimated). Throws
// std::runtime_error("view <name>: <problem>") when a view cannot be read, or "<problem>" when the
// recovery fails.
PhotoSetResponse recover_photo_set_response(const std::vector<const PhotoView*>& views, const RecoveryOptions& options,
                                            Alignment align, const std::optional<ResponseCurve>& curve = std::nullopt);

struct ViewMerge {
  BracketSet brackets;
  std::vector<cv::Point> shifts;  // per bracket, (0, 0) without alignment
  AlignmentResult alignment;      // what registration found and did
  NoiseModel noise;
  MergedImage image;
  double seconds_load = 0, seconds_merge = 0;  // loading + alignment + noise estimate; the merge
  std::string input_colour_space;              // what image was converted from ("": the working space)
};

// `noise` nullopt: estimated from this view alone. `vignetting`, when given, is divided out of the
// merged radiance and variance (hdr/vignetting.h). Throws std::runtime_error("view <name>: ...")
// when the photos' bit depth is not the curve's.
ViewMerge merge_photo_view(const PhotoView& view, const ResponseCurve& curve, const std::optional<NoiseModel>& noise,
                           Alignment align, const MergeOptions& options = {}, const Vignetting* vignetting = nullptr);

// How rsibr hdr and the hdr step of rsibr process merge a view.
struct ViewMergeSettings {
  std::optional<NoiseModel> noise;  // nullopt: estimated from the view alone
  Alignment align = Alignment::automatic;
  MergeOptions merge;
  const Vignetting* vignetting = nullptr;  // divided out when given
  std::optional<cv::Vec3f> white_balance;  // the user's gains on top of the camera's own
  std::string input_colour_space;          // the user's choice ("": none)
  std::string camera_colour_space;         // the photo set's camera.colour_space ("": none)
};

// merge_photo_view, then the user's white balance, then the working space: from the user's input
// colour space, else (RAW excepted: developed to linear Rec.709) the photo set's
// (hdr/merged_colour.h). Same throws as merge_photo_view.
ViewMerge merge_view_radiance(const PhotoView& view, const ResponseCurve& curve, const ViewMergeSettings& settings);

}  // namespace rsibr
