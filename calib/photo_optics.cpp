#include "calib/photo_optics.h"

#include <exiv2/exiv2.hpp>
#include <lensfun/lensfun.h>
#include <libraw/libraw.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <vector>
#include <memory>
#include <mutex>
#include <stdexcept>

namespace rsibr {
namespace {

constexpr double kFullFrameDiagonalMm = 43.266615305567875;  // hypot(36, 24)
constexpr double kFocusSigma = 0.03;

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

// lensfun's database, loaded once (its files under /usr/share/lensfun).
const lfDatabase* lens_database() {
  static std::once_flag once;
  static lfDatabase* db = nullptr;
  std::call_once(once, [] {
    db = lf_db_new();
    if (db && lf_db_load(db) != LF_NO_ERROR) {
      lf_db_destroy(db);
      db = nullptr;
    }
  });
  return db;
}

}  // namespace

PhotoOptics read_photo_optics(const std::filesystem::path& image) {
  PhotoOptics o;
  bool exif_read = false;
  try {
    auto img = Exiv2::ImageFactory::open(image.string());
    img->readMetadata();
    const Exiv2::ExifData& exif = img->exifData();
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
    if (const lfDatabase* db = lens_database()) {
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
  const lfDatabase* db = lens_database();
  if (!db) return std::nullopt;
  const lfCamera** cams = lf_db_find_cameras(db, o.make.c_str(), o.model.c_str());
  const lfCamera* cam = cams && cams[0] ? cams[0] : nullptr;
  const lfLens** lenses = lf_db_find_lenses_hd(db, cam, nullptr, o.lens.c_str(), 0);
  std::optional<LensfunVignetting> out;
  if (lenses && lenses[0]) {
    const lfLens* lens = lenses[0];
    lfLensCalibVignetting calib;
    const float crop = cam ? cam->CropFactor : lens->CropFactor;
    if (lf_lens_interpolate_vignetting(lens, float(*o.focal_mm), float(*o.aperture), float(distance_m), &calib) &&
        crop > 0) {
      // lensfun's correction of a flat field of ones is 1 / v: sampled on a grid of rows, fitted.
      lfModifier* mod = lf_modifier_new(lens, crop, width, height);
      const int flags = lf_modifier_initialize(mod, lens, LF_PF_F32, float(*o.focal_mm), float(*o.aperture),
                                               float(distance_m), 1.0f, lens->Type, LF_MODIFY_VIGNETTING, 0);
      if (flags & LF_MODIFY_VIGNETTING) {
        const double cx = 0.5 * (width - 1), cy = 0.5 * (height - 1);
        const double rc = std::hypot(std::max(cx, width - 1 - cx), std::max(cy, height - 1 - cy));
        const int step = std::max(1, std::min(width, height) / 64);
        Eigen::Matrix3d AtA = Eigen::Matrix3d::Zero();
        Eigen::Vector3d Atb = Eigen::Vector3d::Zero();
        std::vector<std::pair<double, double>> samples;  // (r^2, v)
        std::vector<float> row(std::size_t(width) * 3);
        for (int y = 0; y < height; y += step) {
          std::fill(row.begin(), row.end(), 1.0f);
          lf_modifier_apply_color_modification(mod, row.data(), 0.0f, float(y), width, 1,
                                               LF_CR_3(RED, GREEN, BLUE), int(row.size() * sizeof(float)));
          for (int x = 0; x < width; x += step) {
            const double g = row[std::size_t(x) * 3 + 1];
            if (!(g > 0) || !std::isfinite(g)) continue;
            const double r2 = (std::pow(x - cx, 2) + std::pow(y - cy, 2)) / (rc * rc), v = 1.0 / g;
            const Eigen::Vector3d a(r2, r2 * r2, r2 * r2 * r2);
            AtA += a * a.transpose();
            Atb += a * (v - 1);
            samples.push_back({r2, v});
          }
        }
        const Eigen::Vector3d k = AtA.ldlt().solve(Atb);
        if (k.allFinite() && !samples.empty()) {
          LensfunVignetting lv;
          lv.k = {k[0], k[1], k[2]};
          const std::string maker = lens->Maker ? lf_mlstr_get(lens->Maker) : "", model = lens->Model ? lf_mlstr_get(lens->Model) : "";
          lv.lens = model.rfind(maker, 0) == 0 ? model : maker + " " + model;  // models usually start with the maker
          double s2 = 0;
          for (const auto& [r2, v] : samples) {
            const double fit = 1 + r2 * (k[0] + r2 * (k[1] + r2 * k[2]));
            s2 += std::pow(fit / v - 1, 2);
          }
          lv.fit_rms = std::sqrt(s2 / double(samples.size()));
          out = lv;
        }
      }
      lf_modifier_destroy(mod);
    }
  }
  lf_free(lenses);
  lf_free(cams);
  return out;
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
