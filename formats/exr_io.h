// Reading and writing environment maps: OpenEXR (any channel type, read by channel name), and
// Radiance .hdr on input. Provenance travels in the header as rsibr.* string attributes.
//
// Layout of an input file: the standard `envmap` attribute (lat-long, cube), else the
// `rsibr.layout` attribute, else the caller's hint, else the shape (2:1 lat-long, 1:6 cube);
// anything else is an error that asks for --layout. Pixels are converted from the file's
// `chromaticities` (Rec.709/D65 when absent) to the working space.
#pragma once

#include "core/env_map.h"
#include "core/texel_audit.h"

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace rsibr {

struct EnvReadReport {
  std::string format;         // "exr" or "hdr"
  std::string channels;       // channel names and types as stored, e.g. "B:half G:half R:half"
  std::string compression;    // EXR compression name
  std::string layout_source;  // "envmap attribute", "rsibr.layout attribute", "--layout", "shape"
  bool chromaticities_converted = false;
  TexelAudit texels;  // NaN, Inf, huge and negative values, over all channels
};

// Throws FileError (formats/file_error.h: "<path>: <problem>") on any failure.
EnvMap read_environment(const std::string& path, std::optional<LayoutKind> layout_hint = std::nullopt,
                        EnvReadReport* report = nullptr);

// The rule for an environment a computation reads (bake, reference, plan, render, Python's
// read_environment): lossy-codec ringing, the negative values `report` counted, folded into their
// positive neighbours (remove_negative_ringing: energy kept). Returns the warning to show ("" when
// there was none): "<path>: N negative values (lossy-compression ringing) folded into their
// positive neighbours (integral changed by X%)". `already_folded`: sanitize_texels ran (it folds
// too, after zeroing NaN and Inf, so no clean integral before it is known and none is given).
std::string fold_environment_ringing(EnvMap& env, const std::string& path, const EnvReadReport& report,
                                     bool already_folded);

struct ExrWriteOptions {
  bool half = false;  // half float output; values beyond +-65504 are an error, never a silent Inf
};

// More channels beside the pixels: (name, CV_32FC1 of the map's size), stored like them (e.g. a
// probe's confidence and flags). read_environment reads R, G, B (or Y) and ignores them.
using ExrExtraChannels = std::vector<std::pair<std::string, cv::Mat>>;

// Writes atomically (temporary name, then rename). Writes `envmap` for lat-long and cube,
// `rsibr.layout` always, Rec.709 `chromaticities`, and map.attributes as string attributes
// (names must stay under 32 characters). Throws FileError(path, problem).
void write_environment(const std::string& path, const EnvMap& map, const ExrWriteOptions& options = {},
                       const ExrExtraChannels& extra_channels = {});

}  // namespace rsibr
