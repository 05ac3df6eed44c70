#include "hdr/photo_set_merge.h"

#include "hdr/alignment.h"

#include <chrono>
#include <stdexcept>

namespace rsibr {

PhotoSetResponse recover_photo_set_response(const std::vector<const PhotoView*>& views, const RecoveryOptions& options,
                                            bool align) {
  if (views.empty()) throw std::invalid_argument("recover_photo_set_response: no views");
  PhotoSetResponse r;
  r.from = views.front();
  for (const PhotoView* v : views)
    if (v->brackets.size() > r.from->brackets.size()) r.from = v;
  BracketSet b = load_brackets(*r.from);
  if (align) align_brackets(b);
  if (options.model == "identity") {
    r.recovery.curve = ResponseCurve::identity(b.max_code);
    return r;
  }
  try {
    r.recovery = recover_response(b, options);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error("view " + r.from->name + ": " + e.what());
  }
  return r;
}

ViewMerge merge_photo_view(const PhotoView& view, const ResponseCurve& curve, const std::optional<NoiseModel>& noise,
                           bool align, const MergeOptions& options, const Vignetting* vignetting) {
  const auto t0 = std::chrono::steady_clock::now();
  ViewMerge m;
  m.brackets = load_brackets(view);
  const BracketSet& b = m.brackets;
  if (b.max_code != curve.max_code)
    throw std::runtime_error("view " + view.name + ": " + std::to_string(b.max_code == 255 ? 8 : 16) +
                             "-bit photos, but the response curve is for " +
                             std::to_string(curve.max_code == 255 ? 8 : 16) + "-bit input");
  m.shifts.assign(b.size(), cv::Point(0, 0));
  if (align) m.shifts = align_brackets(m.brackets);
  m.noise = noise ? *noise : estimate_noise(b, curve, default_saturation_code(b.max_code));
  const auto t1 = std::chrono::steady_clock::now();
  m.image = merge_brackets(b, curve, m.noise, options);
  if (vignetting) divide_vignetting(m.image, *vignetting);
  const auto t2 = std::chrono::steady_clock::now();
  m.seconds_load = std::chrono::duration<double>(t1 - t0).count();
  m.seconds_merge = std::chrono::duration<double>(t2 - t1).count();
  return m;
}

}  // namespace rsibr
