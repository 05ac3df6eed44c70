// The lens of a shoot that brings neither chessboards nor a camera model, from what the photos
// themselves say: the EXIF focal length (exiv2; LibRaw's for RAW files exiv2 cannot read), the
// 35 mm-equivalent focal length, and the camera's crop factor from the lensfun database.
//
// A pinhole with the principal point at the image centre and
//   f_px = f35 * hypot(W, H) / hypot(36 mm, 24 mm)
// (the 35 mm equivalent is defined on the diagonal), f35 = FocalLengthIn35mmFilm, else
// FocalLength * lensfun's crop factor. Its stated uncertainty (1 sigma, relative):
//   sqrt(rounding^2 + convention^2 + focus^2), rounding = 0.29 mm / f35 (EXIF stores whole mm),
//   convention = half the gap between the diagonal and the width definitions for this aspect
//   ratio (cameras differ), focus = 3% (FocalLength is nominal, at infinity; a ball a metre
//   away is focused closer and the image is larger by f / (d - f)).
// No distortion is modelled: the JSON says so. Where lensfun has a distortion profile of the lens
// the EXIF names, lensfun_from_optics gives it instead (core/lensfun_lens.h).
#pragma once

#include "core/lens_model.h"
#include "core/lensfun_lens.h"

#include <filesystem>
#include <optional>
#include <string>

namespace rsibr {

struct PhotoOptics {
  std::string make, model, lens;      // EXIF Make, Model, LensModel (may be empty)
  std::optional<double> focal_mm;     // FocalLength
  std::optional<double> focal_35mm;   // FocalLengthIn35mmFilm
  std::optional<double> aperture;     // FNumber
  std::optional<double> crop_factor;  // lensfun's, for make + model
  std::string crop_camera;            // the lensfun entry it came from
};

// Never throws for missing metadata (the fields stay empty); throws std::runtime_error("<file>:
// ...") when the file cannot be read at all.
PhotoOptics read_photo_optics(const std::filesystem::path& image);

struct OpticsLens {
  LensModel lens = LensModel::pinhole(1, 2, 2);
  double focal_px = 0, sigma_relative = 0;  // 1 sigma of f_px, relative
  std::string source;                       // "FocalLengthIn35mmFilm" or "FocalLength x crop factor (lensfun: ...)"
};

// Nullopt when the metadata gives no focal length this can use.
std::optional<OpticsLens> pinhole_from_optics(const PhotoOptics& optics, int width, int height);

// lensfun's distortion profile of the photo's lens (EXIF Make, Model, LensModel, FocalLength) as
// an mrcal model (core/lensfun_lens.h), the focal length paraxial with the crop factor of the
// camera. Its stated uncertainty: sqrt(focus^2 + crop^2), focus as for the pinhole (3%), crop =
// 0.5% (lensfun's crop factors are per camera model, to 3 digits). Nullopt with *why (when given)
// set when the metadata lacks the focal length or lensfun the camera, the lens or its profile.
std::optional<OpticsLens> lensfun_from_optics(const PhotoOptics& optics, int width, int height,
                                              std::string* why = nullptr);

// The lens of a shoot with no chessboards and no model, from one photo's metadata: lensfun's
// profile of the lens its EXIF names, else the EXIF pinhole. source "lensfun" or "exif";
// lensfun_why: why lensfun's profile was not used (empty when it was). Nullopt when the metadata
// has no usable focal length (read_photo_optics's errors propagate).
struct MetadataLens {
  OpticsLens lens;
  std::string source, lensfun_why;
  PhotoOptics optics;
};
std::optional<MetadataLens> metadata_lens(const std::filesystem::path& photo, int width, int height);

// lensfun's vignetting of the photo's lens (core/lensfun_lens.h lensfun_vignetting) at the EXIF
// focal length and aperture; nullopt when the EXIF lacks either or the lens model.
std::optional<LensfunVignetting> lensfun_vignetting(const PhotoOptics& optics, int width, int height,
                                                    double distance_m = 1.0);

}  // namespace rsibr
