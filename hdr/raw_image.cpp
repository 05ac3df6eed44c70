#include "hdr/raw_image.h"

#include "core/parallel.h"

#include <libraw/libraw.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>

namespace rsibr {
namespace {

// Codes at or above are a clipped camera channel (the demosaic of a fully clipped neighbourhood
// can land a few codes short of the top).
constexpr int kCameraClip = 65535 - 16;
// The demosaic (AHD) reads up to 2 px around a pixel: a clipped sample pollutes that far.
constexpr int kClipSpread = 2;

struct ProcessedImageDeleter {
  void operator()(libraw_processed_image_t* p) const { LibRaw::dcraw_clear_mem(p); }
};

void check(int code, const std::filesystem::path& file, const char* step) {
  if (code != LIBRAW_SUCCESS)
    throw std::runtime_error(file.string() + ": cannot " + step + " the RAW file: " + libraw_strerror(code));
}

}  // namespace

bool is_raw_file(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  static const char* const kRaw[] = {".dng", ".cr2", ".cr3", ".crw", ".nef", ".nrw", ".arw", ".srf",
                                     ".sr2", ".raf", ".orf", ".rw2", ".pef", ".srw", ".x3f", ".3fr",
                                     ".iiq", ".rwl", ".mrw", ".kdc", ".dcr", ".erf", ".mef", ".mos"};
  return std::any_of(std::begin(kRaw), std::end(kRaw), [&](const char* e) { return ext == e; });
}

cv::Mat camera_to_output_codes(const cv::Mat& camera, const Mat3& rgb_from_camera, cv::Mat& saturated) {
  if (camera.type() != CV_16UC3) throw std::invalid_argument("camera_to_output_codes: camera must be CV_16UC3");
  // Clipped anywhere in the pixel's demosaic neighbourhood.
  cv::Mat clipped(camera.size(), CV_8UC1);
  for (int y = 0; y < camera.rows; ++y) {
    const cv::Vec3w* in = camera.ptr<cv::Vec3w>(y);
    unsigned char* m = clipped.ptr<unsigned char>(y);
    for (int x = 0; x < camera.cols; ++x)
      m[x] = (in[x][0] >= kCameraClip || in[x][1] >= kCameraClip || in[x][2] >= kCameraClip) ? 255 : 0;
  }
  cv::dilate(clipped, saturated,
             cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * kClipSpread + 1, 2 * kClipSpread + 1)));
  cv::Mat out(camera.size(), CV_16UC3);
  float M[9];
  for (int i = 0; i < 9; ++i) M[i] = float(rgb_from_camera(i / 3, i % 3));
  parallel_for_rows(camera.rows, [&](int y) {
    const cv::Vec3w* in = camera.ptr<cv::Vec3w>(y);
    cv::Vec3w* o = out.ptr<cv::Vec3w>(y);
    for (int x = 0; x < camera.cols; ++x) {
      const float c0 = in[x][0], c1 = in[x][1], c2 = in[x][2];
      for (int r = 0; r < 3; ++r) {
        const float v = M[3 * r] * c0 + M[3 * r + 1] * c1 + M[3 * r + 2] * c2;
        o[x][r] = std::uint16_t(std::lround(std::clamp(v, 0.f, 65535.f)));
      }
      for (int c = 0; c < 3; ++c)
        if (in[x][c] >= kCameraClip) o[x][c] = 65535;
    }
  });
  return out;
}

RawImage read_raw_image(const std::filesystem::path& file, const RawOptions& options) {
  auto raw = std::make_unique<LibRaw>();
  libraw_output_params_t& p = raw->imgdata.params;
  p.output_color = 0;  // the camera's RGB: the matrix is applied here, in float, unclipped
  p.output_bps = 16;
  p.gamm[0] = p.gamm[1] = 1.0;
  p.no_auto_bright = 1;
  p.bright = 1.0f;
  p.highlight = 0;           // clip every channel at the white level after white balance
  p.adjust_maximum_thr = 0;  // the file's white level, whatever the data reach
  p.user_qual = 3;           // AHD
  p.use_camera_matrix = 1;
  if (options.white_balance) {
    const Vec3 wb = *options.white_balance;
    if (!(wb.minCoeff() > 0 && wb.allFinite()))
      throw std::invalid_argument(file.string() + ": white balance multipliers must be positive");
    p.use_camera_wb = 0;
    p.user_mul[0] = float(wb[0]), p.user_mul[1] = float(wb[1]), p.user_mul[2] = float(wb[2]),
    p.user_mul[3] = float(wb[1]);
  } else {
    p.use_camera_wb = 1;
  }
  check(raw->open_file(file.c_str()), file, "open");
  check(raw->unpack(), file, "unpack");
  // The file's levels, before developing subtracts the black.
  const auto& c0 = raw->imgdata.color;
  const int file_black = int(c0.black) + int(std::min({c0.cblack[0], c0.cblack[1], c0.cblack[2], c0.cblack[3]}));
  const int file_white = int(c0.maximum);
  check(raw->dcraw_process(), file, "develop");
  int code = LIBRAW_SUCCESS;
  std::unique_ptr<libraw_processed_image_t, ProcessedImageDeleter> img(raw->dcraw_make_mem_image(&code));
  check(code, file, "develop");
  if (!img || img->type != LIBRAW_IMAGE_BITMAP || img->colors != 3 || img->bits != 16)
    throw std::runtime_error(file.string() + ": the RAW file did not develop to a 16-bit RGB image");
  const cv::Mat camera = cv::Mat(img->height, img->width, CV_16UC3, img->data).clone();

  RawImage out;
  RawInfo& info = out.info;
  const auto& d = raw->imgdata;
  info.make = d.idata.make;
  info.model = d.idata.model;
  info.black = file_black;
  info.white = file_white;
  // LibRaw's multipliers after developing (pre_mul), scaled so the smallest is 1.
  Vec3 wb(d.color.pre_mul[0], d.color.pre_mul[1], d.color.pre_mul[2]);
  if (wb.minCoeff() > 0) info.white_balance = wb / wb.minCoeff();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) info.rgb_from_camera(r, c) = d.color.rgb_cam[r][c];
  // A camera LibRaw has no matrix for leaves rgb_cam as the identity: the output is then the
  // camera's own RGB, which is what the identity stands for.
  info.exposure_s = d.other.shutter > 0 ? d.other.shutter : 0.0;
  info.iso = d.other.iso_speed > 0 ? d.other.iso_speed : 0.0;
  info.aperture = d.other.aperture > 0 ? d.other.aperture : 0.0;
  out.codes = camera_to_output_codes(camera, info.rgb_from_camera, out.saturated);
  info.saturated_fraction = camera.total() ? double(cv::countNonZero(out.saturated)) / double(camera.total()) : 0.0;
  return out;
}

}  // namespace rsibr
