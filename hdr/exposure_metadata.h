// Exposure metadata of one bracket: from photoset.yaml, or from the file's EXIF (exiv2) for the
// values the YAML leaves out. The relative exposure follows the project's convention
// (formats/photo_set.h): e = t * (iso/100) / N^2, a pixel records X = L * e * k.
#pragma once

#include "formats/photo_set.h"

#include <string>

namespace rsibr {

struct ResolvedExposure {
  double exposure_s = 0;  // shutter time, seconds (> 0)
  double iso = 100;
  double aperture = 1;  // f-number
  double relative = 0;  // t * (iso/100) / N^2
  std::string source;   // "yaml", "exif" or "yaml+exif" (RAW brackets: "raw", "yaml+raw", "raw+exif", ...)
};

// Values present in `photo` win; missing ones are read from the file's EXIF (ExposureTime,
// ISOSpeedRatings, FNumber; in the EXIF IFD, else in IFD 0 as TIFF/EP writes them). ISO and aperture default to 100 and 1 when neither source has them
// (they are then common factors of every bracket). Throws std::runtime_error("<file>: ...") when
// the shutter time is in neither, or EXIF values are not positive and finite.
ResolvedExposure resolve_exposure(const BracketPhoto& photo);

}  // namespace rsibr
