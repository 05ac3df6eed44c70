#include "hdr/photo_set_merge.h"

#include "hdr/merged_colour.h"

#include "hdr/alignment.h"
#include "hdr/bracket_statistics.h"

#include "core/srgb_curve.h"

#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace rsibr {

PhotoSetResponse recover_photo_set_response(const std::vector<const PhotoView*>& views, const RecoveryOptions& options,
                                            Alignment align, const std::optional<ResponseCurve>& curve) {
  if (views.empty()) throw std::invalid_argument("recover_photo_set_response: no views");
  PhotoSetResponse r;
  BracketStatistics stats(int(views.size()), 4 * options.samples);
  std::size_t raw_views = 0;
  for (const PhotoView* v : views) {
    try {
      BracketSet b = load_brackets(*v, align != Alignment::off);
      if (b.raw) ++raw_views;
      align_brackets(b, align);
      stats.add(b);
      if (b.size() >= 2) r.from.push_back(v);
    } catch (const std::runtime_error& e) {
      throw std::runtime_error("view " + v->name + ": " + e.what());
    }
  }
  if (raw_views > 0 && raw_views < views.size())
    throw std::runtime_error(std::to_string(raw_views) + " of " + std::to_string(views.size()) +
                             " views are camera RAW files and the others are not: one response cannot serve both");
  const bool raw = raw_views == views.size();
  if (curve) {
    r.recovery.curve = *curve;
  } else if (options.model == "identity" || (raw && options.model == "auto")) {
    // RAW files are linear by construction (hdr/raw_image.h): no response to recover, and their
    // saturation is the top code.
    r.recovery.curve = ResponseCurve::identity(stats.max_code);
    if (raw) r.recovery.curve.saturation = {65535, 65535, 65535};
    for (int c = 0; c < 3; ++c)
      if (options.saturation_code[std::size_t(c)] > 0)
        r.recovery.curve.saturation[std::size_t(c)] = options.saturation_code[std::size_t(c)];
    r.recovery.chosen = raw ? "linear (camera RAW: identity response)" : "identity (given)";
    r.recovery.saturation.code = {r.recovery.curve.saturation_code(0), r.recovery.curve.saturation_code(1),
                                  r.recovery.curve.saturation_code(2)};
    r.recovery.saturation.source = raw ? "raw white level" : "default";
    r.recovery.margin_sigmas = std::numeric_limits<double>::infinity();
  } else if (r.from.empty() && options.model == "auto") {
    // One exposure per view: no response can be recovered from one photo, so the one photos are
    // encoded with is stated (sRGB, core/srgb_curve.h, the default of JPEG, HEIF and PNG writers),
    // at u = z / max_code. Pixels at the top code stay clipped, merged as lower bounds.
    r.recovery.curve = ResponseCurve::sampled("srgb", stats.max_code, stats.max_code == 255 ? 256 : 1024,
                                              [](int, double u) { return srgb_decode(u); });
    r.recovery.curve.validate();
    r.recovery.chosen = "sRGB (stated: one exposure per view, nothing to recover a response from)";
    r.recovery.saturation.code = {r.recovery.curve.saturation_code(0), r.recovery.curve.saturation_code(1),
                                  r.recovery.curve.saturation_code(2)};
    r.recovery.saturation.source = "default";
    r.recovery.margin_sigmas = std::numeric_limits<double>::infinity();
  } else {
    r.recovery = recover_response(stats, options);
  }
  r.noise = estimate_noise(stats, r.recovery.curve);
  return r;
}

ViewMerge merge_photo_view(const PhotoView& view, const ResponseCurve& curve, const std::optional<NoiseModel>& noise,
                           Alignment align, const MergeOptions& options, const Vignetting* vignetting) {
  const auto t0 = std::chrono::steady_clock::now();
  ViewMerge m;
  m.brackets = load_brackets(view, align != Alignment::off);
  const BracketSet& b = m.brackets;
  if (b.max_code != curve.max_code)
    throw std::runtime_error("view " + view.name + ": " + std::to_string(b.max_code == 255 ? 8 : 16) +
                             "-bit photos, but the response curve is for " +
                             std::to_string(curve.max_code == 255 ? 8 : 16) + "-bit input");
  m.alignment = align_brackets(m.brackets, align);
  m.shifts = m.alignment.shifts;
  m.noise = noise ? *noise : estimate_noise(std::vector<const BracketSet*>{&b}, curve);
  const auto t1 = std::chrono::steady_clock::now();
  m.image = merge_brackets(b, curve, m.noise, options);
  if (vignetting) divide_vignetting(m.image, *vignetting);
  const auto t2 = std::chrono::steady_clock::now();
  m.seconds_load = std::chrono::duration<double>(t1 - t0).count();
  m.seconds_merge = std::chrono::duration<double>(t2 - t1).count();
  return m;
}

ViewMerge merge_view_radiance(const PhotoView& view, const ResponseCurve& curve, const ViewMergeSettings& settings) {
  ViewMerge m = merge_photo_view(view, curve, settings.noise, settings.align, settings.merge, settings.vignetting);
  if (settings.white_balance) apply_white_balance(m.image, *settings.white_balance);
  // A RAW file is developed to linear Rec.709 whatever the photo set says; only the user's own
  // choice overrides that.
  const std::string given = !settings.input_colour_space.empty() ? settings.input_colour_space
                            : m.brackets.raw                     ? std::string()
                                                                 : settings.camera_colour_space;
  m.input_colour_space = merged_colour_space(given, m.brackets.raw);
  merged_to_working_space(m.image, m.input_colour_space);
  return m;
}

}  // namespace rsibr
