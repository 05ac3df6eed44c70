#include "hdr/exposure_metadata.h"

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
  const Exiv2::Rational q = it->toRational(0);
  const double v = q.second != 0 ? double(q.first) / double(q.second) : double(it->toFloat(0));
  if (!std::isfinite(v) || v <= 0)
    throw std::runtime_error(file + ": EXIF " + key + " is not a positive number (" + it->toString() + ")");
  return v;
}

ExifExposure read_exif(const std::string& file) {
  ExifExposure out;
  try {
    auto image = Exiv2::ImageFactory::open(file);
    image->readMetadata();
    const Exiv2::ExifData& exif = image->exifData();
    out.exposure_s = exif_number(exif, "Exif.Photo.ExposureTime", file);
    out.iso = exif_number(exif, "Exif.Photo.ISOSpeedRatings", file);
    out.aperture = exif_number(exif, "Exif.Photo.FNumber", file);
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
  if (!t) throw std::runtime_error(file + ": no exposure time (neither exposure_s in photoset.yaml nor EXIF ExposureTime)");
  r.exposure_s = *t;
  r.iso = pick(photo.iso, exif ? exif->iso : std::nullopt).value_or(100.0);
  r.aperture = pick(photo.aperture, exif ? exif->aperture : std::nullopt).value_or(1.0);
  r.relative = r.exposure_s * (r.iso / 100.0) / (r.aperture * r.aperture);
  const bool used_yaml = photo.exposure_s || photo.iso || photo.aperture;
  r.source = used_exif ? (used_yaml ? "yaml+exif" : "exif") : "yaml";
  return r;
}

}  // namespace rsibr
