#include "hdr/photo_set_merge.h"

#include "hdr/alignment.h"
#include "hdr/bracket_statistics.h"

#include <chrono>
#include <stdexcept>

namespace rsibr {

PhotoSetResponse recover_photo_set_response(const std::vector<const PhotoView*>& views, const RecoveryOptions& options,
                                            bool align, const std::optional<ResponseCurve>& curve) {
  if (views.empty()) throw std::invalid_argument("recover_photo_set_response: no views");
  PhotoSetResponse r;
  BracketStatistics stats(int(views.size()), 4 * options.samples);
  for (const PhotoView* v : views) {
    try {
      BracketSet b = load_brackets(*v);
      if (align) align_brackets(b);
      stats.add(b);
      if (b.size() >= 2) r.from.push_back(v);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error("view " + v->name + ": " + e.what());
    }
  }
  if (curve) {
    r.recovery.curve = *curve;
  } else if (options.model == "identity") {
    r.recovery.curve = ResponseCurve::identity(stats.max_code);
    for (int c = 0; c < 3; ++c)
      if (options.saturation_code[std::size_t(c)] > 0) r.recovery.curve.saturation[std::size_t(c)] = options.saturation_code[std::size_t(c)];
  } else {
    r.recovery = recover_response(stats, options);
  }
  r.noise = estimate_noise(stats, r.recovery.curve);
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
  m.noise = noise ? *noise : estimate_noise(std::vector<const BracketSet*>{&b}, curve);
  const auto t1 = std::chrono::steady_clock::now();
  m.image = merge_brackets(b, curve, m.noise, options);
  if (vignetting) divide_vignetting(m.image, *vignetting);
  const auto t2 = std::chrono::steady_clock::now();
  m.seconds_load = std::chrono::duration<double>(t1 - t0).count();
  m.seconds_merge = std::chrono::duration<double>(t2 - t1).count();
  return m;
}

}  // namespace rsibr
