// The merged view as an OpenEXR file: float32 channels R, G, B (radiance in the working colour
// space), variance.R/.G/.B (variance of each), and clipped, black, ghost (0 or 1; merge.h), with
// Rec.709 `chromaticities` and provenance as rsibr.* string attributes (names < 32 characters).
#pragma once

#include "formats/exr_file.h"
#include "hdr/merge.h"

#include <map>
#include <string>

namespace rsibr {

// Writes atomically. Throws FileError(path, problem), e.g. for a long attribute name or a
// non-finite value (the merge never produces one; this guards the contract).
void write_merged_exr(const std::string& path, const MergedImage& image,
                      const std::map<std::string, std::string>& attributes);

// Whether an EXR part has every channel of a merged view.
bool is_merged_view(const ExrPartIn& part);

// Reads a file written by write_merged_exr (flags rebuilt from the flag channels); the rsibr.*
// attributes go to `attributes` when given. Throws FileError(path, problem).
MergedImage read_merged_exr(const std::string& path, std::map<std::string, std::string>* attributes = nullptr);
// The same from a file already open (its first part). Without `variance` its channels are not
// copied out (the result's variance is empty): calibration reads radiance and flags only.
MergedImage read_merged_exr(const ExrFileIn& file, std::map<std::string, std::string>* attributes = nullptr,
                            bool variance = true);

}  // namespace rsibr
