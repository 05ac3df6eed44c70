// A photo set's views merged the way rsibr hdr and rsibr process both do it: the camera response
// recovered once, from the view with the most brackets (the first on ties), then each view's
// brackets loaded (aligned when asked), its noise estimated (unless given) and merged.
#pragma once

#include "core/photo_set.h"
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
  ResponseRecovery recovery;          // model "identity": the identity curve, no candidates
  const PhotoView* from = nullptr;    // the view it was recovered from
};

// `views` non-empty. options.model "identity" skips the fit (linear input). Throws
// std::runtime_error("view <name>: <problem>") when the recovery fails.
PhotoSetResponse recover_photo_set_response(const std::vector<const PhotoView*>& views, const RecoveryOptions& options,
                                            bool align);

struct ViewMerge {
  BracketSet brackets;
  std::vector<cv::Point> shifts;  // per bracket, (0, 0) without alignment
  NoiseModel noise;
  MergedImage image;
  double seconds_load = 0, seconds_merge = 0;  // loading + alignment + noise estimate; the merge
};

// `vignetting`, when given, is divided out of the merged radiance and variance (hdr/vignetting.h).
// Throws std::runtime_error("view <name>: ...") when the photos' bit depth is not the curve's.
ViewMerge merge_photo_view(const PhotoView& view, const ResponseCurve& curve, const std::optional<NoiseModel>& noise,
                           bool align, const MergeOptions& options = {}, const Vignetting* vignetting = nullptr);

}  // namespace rsibr
