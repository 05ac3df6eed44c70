#include "capture/dng_file.h"
#include "formats/file_error.h"

#include "formats/atomic_file.h"

#include <tiffio.h>

#include <array>
#include <cstdint>
#include <memory>
#include <mutex>
#include <stdexcept>

namespace rsibr {
namespace {

// TIFF/EP's exposure tags in IFD 0 (libtiff knows them only in the EXIF IFD): registered through
// a tag extender, chained to any extender installed before.
constexpr ttag_t kExposureTime = 33434, kFNumber = 33437, kIsoSpeed = 34855;
const TIFFFieldInfo kTiffEpFields[] = {
    {kExposureTime, 1, 1, TIFF_RATIONAL, FIELD_CUSTOM, 1, 0, const_cast<char*>("ExposureTime")},
    {kFNumber, 1, 1, TIFF_RATIONAL, FIELD_CUSTOM, 1, 0, const_cast<char*>("FNumber")},
    {kIsoSpeed, 1, 1, TIFF_SHORT, FIELD_CUSTOM, 1, 0, const_cast<char*>("ISOSpeedRatings")},
};
TIFFExtendProc previous_extender = nullptr;

void tiff_ep_extender(TIFF* tif) {
  TIFFMergeFieldInfo(tif, kTiffEpFields, sizeof kTiffEpFields / sizeof kTiffEpFields[0]);
  if (previous_extender) previous_extender(tif);
}

void install_extender() {
  static std::once_flag once;
  std::call_once(once, [] { previous_extender = TIFFSetTagExtender(tiff_ep_extender); });
}

// CFAPattern's colour codes (TIFF/EP): 0 red, 1 green, 2 blue.
int cfa_channel(const std::string& cfa, int x, int y) {
  const char c = cfa[std::size_t((y & 1) * 2 + (x & 1))];
  return c == 'R' ? 0 : c == 'G' ? 1 : 2;
}

void check_cfa(const std::string& cfa) {
  if (cfa != "RGGB" && cfa != "BGGR" && cfa != "GRBG" && cfa != "GBRG")
    throw std::invalid_argument("DNG: CFA pattern must be RGGB, BGGR, GRBG or GBRG, not '" + cfa + "'");
}

struct TiffCloser {
  void operator()(TIFF* t) const { TIFFClose(t); }
};

}  // namespace

Mat3 dng_colour_matrix(const Mat3& camera_from_rec709) {
  Mat3 xyz_from_rec709;  // IEC 61966-2-1 (sRGB primaries, D65 white)
  xyz_from_rec709 << 0.4124564, 0.3575761, 0.1804375, 0.2126729, 0.7151522, 0.0721750, 0.0193339, 0.1191920, 0.9503041;
  return camera_from_rec709 * xyz_from_rec709.inverse();
}

cv::Mat bayer_mosaic(const cv::Mat& raw, const std::string& cfa) {
  check_cfa(cfa);
  if (raw.type() != CV_16UC3) throw std::invalid_argument("bayer_mosaic: raw must be CV_16UC3");
  cv::Mat out(raw.size(), CV_16UC1);
  for (int y = 0; y < raw.rows; ++y)
    for (int x = 0; x < raw.cols; ++x) out.at<std::uint16_t>(y, x) = raw.at<cv::Vec3w>(y, x)[cfa_channel(cfa, x, y)];
  return out;
}

void write_dng(const std::filesystem::path& file, const cv::Mat& mosaic, const DngInfo& info) {
  check_cfa(info.cfa);
  if (mosaic.type() != CV_16UC1 || mosaic.empty() || mosaic.rows % 2 || mosaic.cols % 2)
    throw std::invalid_argument("DNG: the mosaic must be CV_16UC1 with even, non-zero width and height");
  if (!(info.black >= 0 && info.black < info.white && info.white <= 65535))
    throw std::invalid_argument("DNG: levels must satisfy 0 <= black < white <= 65535");
  if (!(info.exposure_s > 0 && info.iso > 0 && info.aperture > 0))
    throw std::invalid_argument("DNG: exposure, ISO and aperture must be positive");
  install_extender();
  write_atomically(file, [&](const std::string& tmp) {
    std::unique_ptr<TIFF, TiffCloser> tif(TIFFOpen(tmp.c_str(), "w"));
    if (!tif) throw std::runtime_error(file.string() + ": cannot open for writing");
    TIFF* t = tif.get();
    bool ok = true;
    auto set = [&](bool r) { ok = ok && r; };
    set(TIFFSetField(t, TIFFTAG_SUBFILETYPE, 0));
    set(TIFFSetField(t, TIFFTAG_IMAGEWIDTH, std::uint32_t(mosaic.cols)));
    set(TIFFSetField(t, TIFFTAG_IMAGELENGTH, std::uint32_t(mosaic.rows)));
    set(TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, 16));
    set(TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, 1));
    set(TIFFSetField(t, TIFFTAG_COMPRESSION, COMPRESSION_NONE));
    set(TIFFSetField(t, TIFFTAG_PHOTOMETRIC, PHOTOMETRIC_CFA));
    set(TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG));
    set(TIFFSetField(t, TIFFTAG_ORIENTATION, ORIENTATION_TOPLEFT));
    set(TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, std::uint32_t(std::max(1, 65536 / (2 * mosaic.cols)))));
    set(TIFFSetField(t, TIFFTAG_MAKE, info.make.c_str()));
    set(TIFFSetField(t, TIFFTAG_MODEL, info.model.c_str()));
    set(TIFFSetField(t, TIFFTAG_SOFTWARE, "rsibr synth"));
    const std::uint8_t version[4] = {1, 4, 0, 0}, backward[4] = {1, 1, 0, 0};
    set(TIFFSetField(t, TIFFTAG_DNGVERSION, version));
    set(TIFFSetField(t, TIFFTAG_DNGBACKWARDVERSION, backward));
    const std::string unique = info.make + " " + info.model;
    set(TIFFSetField(t, TIFFTAG_UNIQUECAMERAMODEL, unique.c_str()));
    const std::uint16_t repeat[2] = {2, 2};
    set(TIFFSetField(t, TIFFTAG_CFAREPEATPATTERNDIM, repeat));
    std::uint8_t pattern[4];
    for (int i = 0; i < 4; ++i) pattern[i] = std::uint8_t(cfa_channel(info.cfa, i & 1, i >> 1));
    set(TIFFSetField(t, TIFFTAG_CFAPATTERN, 4, pattern));
    const float black[1] = {float(info.black)};
    set(TIFFSetField(t, TIFFTAG_BLACKLEVEL, 1, black));
    const std::uint32_t white[1] = {std::uint32_t(info.white)};
    set(TIFFSetField(t, TIFFTAG_WHITELEVEL, 1, white));
    float matrix[9];
    for (int i = 0; i < 9; ++i) matrix[i] = float(info.camera_from_xyz(i / 3, i % 3));
    set(TIFFSetField(t, TIFFTAG_COLORMATRIX1, 9, matrix));
    set(TIFFSetField(t, TIFFTAG_CALIBRATIONILLUMINANT1, 21));  // D65
    const float neutral[3] = {float(info.as_shot_neutral[0]), float(info.as_shot_neutral[1]),
                              float(info.as_shot_neutral[2])};
    set(TIFFSetField(t, TIFFTAG_ASSHOTNEUTRAL, 3, neutral));
    set(TIFFSetField(t, kExposureTime, info.exposure_s));
    set(TIFFSetField(t, kFNumber, info.aperture));
    set(TIFFSetField(t, kIsoSpeed, int(std::lround(info.iso))));
    if (!ok) throw std::runtime_error(file.string() + ": libtiff refused a DNG tag");
    cv::Mat row;
    for (int y = 0; y < mosaic.rows; ++y) {
      row = mosaic.row(y).clone();
      if (TIFFWriteScanline(t, row.ptr<std::uint16_t>(), std::uint32_t(y), 0) < 0)
        throw FileError(file.string(), std::string("cannot write row ") + std::to_string(y), {}, FileRole::Output);
    }
    if (!TIFFWriteDirectory(t)) throw FileError(file.string(), "cannot write the directory", {}, FileRole::Output);
  });
}

}  // namespace rsibr
