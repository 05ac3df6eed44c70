// Every OpenEXR file rsibr reads or writes goes through here: float channels by name, one or more
// parts, the attribute types rsibr uses (string, int, V3f, M33f, float vector). The callers (map
// sets, environments, merged views, truth images, renders) say what goes in a file, not how
// OpenEXR stores it.
//
// Writing: ZIP compression (PIZ where a part asks for it), Rec.709 `chromaticities` in every part, written atomically (a
// temporary next to the target, renamed when complete). Attribute names at most 31 characters.
// Reading: the header is checked before OpenEXR sizes anything (check_before_opening), every
// part's data window is checked (checked_data_window), and pixels are read as float whatever
// their stored type. Every error is a FileError naming the file (formats/file_error.h).
#pragma once

#include "formats/file_error.h"
#include "core/vec.h"

#include <opencv2/core.hpp>

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace rsibr {

// Attribute values. Mat3 is stored as M33f with m[row][col] = M(row, col); Vec3 as V3f.
using ExrValue = std::variant<std::string, int, Vec3, Mat3, std::vector<float>>;

// OpenEXR's standard `envmap` attribute.
enum class ExrEnvmap { None, LatLong, Cube };

// Lossless compressions. PIZ (wavelet + Huffman) writes photo-like float images with flag planes
// (merged views) in about half ZIP's time and no larger; ZIP is the default.
enum class ExrCompression { Zip, Piz };

// One channel to write: channel `index` of `image` (CV_32FC(n), index < n).
struct ExrChannelOut {
  std::string name;
  cv::Mat image;
  int index = 0;
};

struct ExrPartOut {
  std::string name;                     // the part's name (required for multi-part files, optional for one part)
  std::vector<ExrChannelOut> channels;  // all of one size, at least one
  std::vector<std::pair<std::string, ExrValue>> attributes;  // names as stored
  ExrEnvmap envmap = ExrEnvmap::None;
  bool half = false;  // store as half float; a finite value beyond +-65504 is an error, never a silent Inf
  ExrCompression compression = ExrCompression::Zip;
};

// Attribute names longer than this break older OpenEXR readers.
inline constexpr std::size_t kMaxAttributeName = 31;

// Whether the file starts with OpenEXR's magic number (false for a file that cannot be read).
bool looks_like_exr(const std::string& path);

// Throws FileError(path, ...) on any failure; nothing is left at `path` or beside it then.
void write_exr(const std::string& path, const std::vector<ExrPartOut>& parts);

// The header of one part as read.
struct ExrPartIn {
  std::string name;                   // "" when the part has none
  int width = 0, height = 0;          // of the data window (checked)
  std::vector<std::string> channels;  // names as stored, in the file's (alphabetical) order
  std::string channel_types;          // names and types, e.g. "B:half G:half R:half"
  std::string compression;            // e.g. "zip", "dwaa (lossy)"
  ExrEnvmap envmap = ExrEnvmap::None;
  // The matrix from the file's primaries to the working space (core/colour.h); nullopt when the
  // file's `chromaticities` are Rec.709/D65 or absent.
  std::optional<Mat3> working_from_file;
  std::map<std::string, ExrValue> attributes;  // the attributes of the types above; others are left out

  bool has_channel(const std::string& c) const;
  // The attribute's value when present with type T, else nullopt.
  template <typename T>
  std::optional<T> get(const std::string& attribute) const {
    const auto it = attributes.find(attribute);
    if (it == attributes.end() || !std::holds_alternative<T>(it->second)) return std::nullopt;
    return std::get<T>(it->second);
  }
  // The string attributes whose names start with `prefix`, keyed by the rest of the name.
  std::map<std::string, std::string> strings_with_prefix(const std::string& prefix) const;
};

// An EXR file opened for reading: every part's header up front, pixels on request.
// Whether every part of the EXR file at `path` opens and all its scan lines decode (the read-back
// of formats/written_file_check.h). Never throws.
bool exr_reads_back(const std::string& path) noexcept;

class ExrFileIn {
 public:
  explicit ExrFileIn(const std::string& path);  // a regular file, checked before OpenEXR opens it
  ~ExrFileIn();
  ExrFileIn(const ExrFileIn&) = delete;
  ExrFileIn& operator=(const ExrFileIn&) = delete;

  const std::string& path() const { return path_; }
  const std::vector<ExrPartIn>& parts() const { return parts_; }
  // The named channels of part `part` as one CV_32FC(n) image, n = channels.size(),
  // distinct names; a channel the part lacks is an error naming it.
  cv::Mat read(int part, const std::vector<std::string>& channels) const;

 private:
  struct Impl;
  std::string path_;
  std::vector<ExrPartIn> parts_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rsibr
