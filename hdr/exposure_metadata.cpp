#include "hdr/exposure_metadata.h"

#include "hdr/photo_exif.h"

#include <exiv2/exiv2.hpp>

#include <cmath>
#include <optional>
#include <stdexcept>

namespace rsibr {
namespace {

struct ExifExposure {
  std::optional<double> exposure_s, iso, aperture;
};

std::optional<double> exif_number(const Exiv2::ExifData& exif, const char* key, const std::string& file) {
  const auto it = exif.findKey(Exiv2::ExifKey(key));
  if (it == exif.end() || it->count() == 0) return std::nullopt;
  // Rationals as exact as double allows (toFloat would round through float).
  // An unsigned rational whose denominator is 2^31 or more reads as negative through the signed
  // pair (libtiff writes 1/400 s as 5368709/2^31): those go through toFloat.
  const Exiv2::Rational q = it->toRational(0);
  const double v = q.second > 0 && q.first >= 0 ? double(q.first) / double(q.second) : double(it->toFloat(0));
  if (!std::isfinite(v) || v <= 0)
    throw std::runtime_error(file + ": EXIF " + key + " is not a positive number (" + it->toString() + ")");
  return v;
}

ExifExposure read_exif(const std::string& file) {
  ExifExposure out;
  try {
    const Exiv2::ExifData exif = read_photo_exif(file);
    // The EXIF IFD, else IFD 0 (TIFF/EP and some RAW formats keep them there).
    auto either = [&](const char* photo, const char* image) {
      const auto v = exif_number(exif, photo, file);
      return v ? v : exif_number(exif, image, file);
    };
    out.exposure_s = either("Exif.Photo.ExposureTime", "Exif.Image.ExposureTime");
    out.iso = either("Exif.Photo.ISOSpeedRatings", "Exif.Image.ISOSpeedRatings");
    out.aperture = either("Exif.Photo.FNumber", "Exif.Image.FNumber");
  } catch (const Exiv2::Error& e) {
    throw std::runtime_error(file + ": cannot read EXIF: " + e.what());
  }
  return out;
}

}  // namespace

ResolvedExposure resolve_exposure(const BracketPhoto& photo) {
  ResolvedExposure r;
  const std::string file = photo.file.string();
  std::optional<ExifExposure> exif;
  if (!photo.exposure_s || !photo.iso || !photo.aperture) exif = read_exif(file);
  bool used_exif = false;
  auto pick = [&](const std::optional<double>& yaml, const std::optional<double>& from_exif) -> std::optional<double> {
    if (yaml) return yaml;
    if (from_exif) used_exif = true;
    return from_exif;
  };
  const auto t = pick(photo.exposure_s, exif ? exif->exposure_s : std::nullopt);
  if (!t)
    throw std::runtime_error(file + ": no exposure time (neither exposure_s in photoset.yaml nor EXIF ExposureTime)");
  r.exposure_s = *t;
  r.iso = pick(photo.iso, exif ? exif->iso : std::nullopt).value_or(100.0);
  r.aperture = pick(photo.aperture, exif ? exif->aperture : std::nullopt).value_or(1.0);
  r.relative = r.exposure_s * (r.iso / 100.0) / (r.aperture * r.aperture);
  const bool used_yaml = photo.exposure_s || photo.iso || photo.aperture;
  r.source = used_exif ? (used_yaml ? "yaml+exif" : "exif") : "yaml";
  return r;
}

}  // namespace rsibr
