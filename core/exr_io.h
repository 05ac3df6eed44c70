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

#include <Imath/ImathBox.h>

#include <optional>
#include <string>
#include <utility>

namespace rsibr {

struct EnvReadReport {
  std::string format;            // "exr" or "hdr"
  std::string channels;          // channel names and types as stored, e.g. "B:half G:half R:half"
  std::string compression;       // EXR compression name
  std::string layout_source;     // "envmap attribute", "rsibr.layout attribute", "--layout", "shape"
  bool chromaticities_converted = false;
  TexelAudit texels;             // NaN, Inf, huge and negative values, over all channels
};

// Throws std::runtime_error("<path>: <problem>") on any failure.
EnvMap read_environment(const std::string& path, std::optional<LayoutKind> layout_hint = std::nullopt,
                        EnvReadReport* report = nullptr);

struct ExrWriteOptions {
  bool half = false;  // half float output; values beyond +-65504 are an error, never a silent Inf
};

// Writes atomically (temporary name, then rename). Writes `envmap` for lat-long and cube,
// `rsibr.layout` always, Rec.709 `chromaticities`, and map.attributes as string attributes
// (names must stay under 32 characters). Throws std::runtime_error("<path>: <problem>").
void write_environment(const std::string& path, const EnvMap& map, const ExrWriteOptions& options = {});

// Every reader of EXR files calls this before OpenEXR opens `path`. OpenEXR sizes its buffers from
// the header: a string attribute that claims 2 GB made OpenEXR 3.1 allocate and clear 2 GB before
// it found the file was 3 KB (found by fuzz/fuzz_map_set), and a data window can claim any size.
// So the header's attributes are walked here first (each must fit in the file, names at most 255
// bytes, at most 1024 attributes and 1024 parts), and OpenEXR's own sanity check is given limits
// (data windows at most 65536, tiles 8192 a side). Throws std::runtime_error("<path>: ...").
void check_exr_before_reading(const std::string& path);

// The data window of an opened file as (width, height), checked to be a size rsibr reads: at least
// 1 x 1, at most 65536 a side and 2^27 pixels (16384 x 8192; 1.6 GB of float RGB). A corrupt or
// hostile header must not size an allocation. Throws std::runtime_error("<path>: ...").
std::pair<int, int> checked_data_window(const Imath::Box2i& data_window, const std::string& path);

// Attribute names longer than this break older OpenEXR readers.
inline constexpr std::size_t kMaxAttributeName = 31;

}  // namespace rsibr
