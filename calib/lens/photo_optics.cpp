#include "calib/lens/photo_optics.h"

#include "core/lensfun_lens.h"

#include "hdr/photo_exif.h"

#include <exiv2/exiv2.hpp>
#include <lensfun/lensfun.h>
#include <libraw/libraw.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>

namespace rsibr {
namespace {

constexpr double kFullFrameDiagonalMm = 43.266615305567875;  // hypot(36, 24)
constexpr double kFocusSigma = 0.03;
constexpr double kCropSigma = 0.005;

std::optional<double> positive(const Exiv2::ExifData& exif, const char* key) {
  const auto it = exif.findKey(Exiv2::ExifKey(key));
  if (it == exif.end() || it->count() == 0) return std::nullopt;
  const double v = it->toFloat(0);
  return std::isfinite(v) && v > 0 ? std::optional<double>(v) : std::nullopt;
}

std::string text(const Exiv2::ExifData& exif, const char* key) {
  const auto it = exif.findKey(Exiv2::ExifKey(key));
  if (it == exif.end()) return {};
  std::string s = it->toString();
  while (!s.empty() && (s.back() == ' ' || s.back() == '\0')) s.pop_back();
  return s;
}

}  // namespace

PhotoOptics read_photo_optics(const std::filesystem::path& image) {
  PhotoOptics o;
  bool exif_read = false;
  try {
    const Exiv2::ExifData exif = read_photo_exif(image.string());
    o.make = text(exif, "Exif.Image.Make");
    o.model = text(exif, "Exif.Image.Model");
    o.lens = text(exif, "Exif.Photo.LensModel");
    o.focal_mm = positive(exif, "Exif.Photo.FocalLength");
    if (!o.focal_mm) o.focal_mm = positive(exif, "Exif.Image.FocalLength");
    o.focal_35mm = positive(exif, "Exif.Photo.FocalLengthIn35mmFilm");
    o.aperture = positive(exif, "Exif.Photo.FNumber");
    exif_read = true;
  } catch (const Exiv2::Error&) {
    // Not a format exiv2 reads (CR3, some RAWs): LibRaw below, or nothing.
  }
  if (!o.focal_mm) {
    auto raw = std::make_unique<LibRaw>();
    if (raw->open_file(image.c_str()) == LIBRAW_SUCCESS) {
      if (raw->imgdata.other.focal_len > 0) o.focal_mm = raw->imgdata.other.focal_len;
      if (!o.aperture && raw->imgdata.other.aperture > 0) o.aperture = raw->imgdata.other.aperture;
      if (o.make.empty()) o.make = raw->imgdata.idata.make;
      if (o.model.empty()) o.model = raw->imgdata.idata.model;
      if (o.lens.empty()) o.lens = raw->imgdata.lens.Lens;
    } else if (!exif_read && !std::filesystem::is_regular_file(image)) {
      throw std::runtime_error(image.string() + ": cannot read the file");
    }
  }
  if (!o.make.empty() || !o.model.empty()) {
    if (const lfDatabase* db = lensfun_database()) {
      const lfCamera** cams = lf_db_find_cameras(db, o.make.c_str(), o.model.c_str());
      if (cams && cams[0] && cams[0]->CropFactor > 0) {
        o.crop_factor = cams[0]->CropFactor;
        o.crop_camera = std::string(lf_mlstr_get(cams[0]->Maker)) + " " + lf_mlstr_get(cams[0]->Model);
      }
      lf_free(cams);
    }
  }
  return o;
}

std::optional<LensfunVignetting> lensfun_vignetting(const PhotoOptics& o, int width, int height, double distance_m) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("lensfun_vignetting: the image size must be positive");
  if (!o.focal_mm || !o.aperture || o.lens.empty()) return std::nullopt;
  return lensfun_vignetting(o.make, o.model, o.lens, *o.focal_mm, *o.aperture, width, height, distance_m);
}

std::optional<OpticsLens> lensfun_from_optics(const PhotoOptics& o, int width, int height, std::string* why) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("lensfun_from_optics: the image size must be positive");
  if (!o.focal_mm) {
    if (why) *why = "the photo's metadata has no FocalLength";
    return std::nullopt;
  }
  const std::optional<LensfunLens> L = lensfun_lens(o.make, o.model, o.lens, *o.focal_mm, width, height, why);
  if (!L) return std::nullopt;
  OpticsLens out;
  out.lens = L->lens;
  out.focal_px = L->focal_px;
  out.sigma_relative = std::hypot(kFocusSigma, kCropSigma);
  char fit[96];
  std::snprintf(fit, sizeof fit, "; %s fitted within %.3f px", L->lens.name().c_str(), L->fit_max_px);
  out.source = "lensfun: " + L->lens_name + " on the " + L->camera + ", " + L->profile + fit;
  return out;
}

std::optional<MetadataLens> metadata_lens(const std::filesystem::path& photo, int width, int height) {
  MetadataLens m;
  m.optics = read_photo_optics(photo);
  std::optional<OpticsLens> l = lensfun_from_optics(m.optics, width, height, &m.lensfun_why);
  if (l) {
    m.source = "lensfun";
    m.lensfun_why.clear();
  } else {
    l = pinhole_from_optics(m.optics, width, height);
    m.source = "exif";
  }
  if (!l) return std::nullopt;
  m.lens = *l;
  return m;
}

std::optional<OpticsLens> pinhole_from_optics(const PhotoOptics& o, int width, int height) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("pinhole_from_optics: the image size must be positive");
  OpticsLens out;
  double f35 = 0;
  if (o.focal_35mm) {
    f35 = *o.focal_35mm;
    out.source = "FocalLengthIn35mmFilm";
  } else if (o.focal_mm && o.crop_factor) {
    f35 = *o.focal_mm * *o.crop_factor;
    out.source = "FocalLength x crop factor " + std::to_string(*o.crop_factor) + " (lensfun: " + o.crop_camera + ")";
  } else {
    return std::nullopt;
  }
  const double diagonal = std::hypot(double(width), double(height));
  out.focal_px = f35 * diagonal / kFullFrameDiagonalMm;
  // The width-based definition of the equivalent, f35 = f * 36 / sensor width, differs from the
  // diagonal one by this factor for this aspect ratio (1 for 3:2).
  const double width_based = 36.0 * diagonal / (double(width) * kFullFrameDiagonalMm);
  const double rounding = 0.29 / f35, convention = 0.5 * std::abs(1.0 - width_based);
  out.sigma_relative = std::sqrt(rounding * rounding + convention * convention + kFocusSigma * kFocusSigma);
  out.lens = LensModel::pinhole(out.focal_px, width, height);
  return out;
}

}  // namespace rsibr
