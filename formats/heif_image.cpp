#include "formats/heif_image.h"

#include "core/lazy_library.h"

#include <libheif/heif.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>

namespace rsibr {
namespace {

const LazyLibrary& libheif() {
  static const LazyLibrary library(RSIBR_HEIF_SONAME, "reading HEIF/HEIC photos");
  return library;
}

// Each libheif function by its C name, its type from the header (a changed signature is a compile
// error here).
#define RSIBR_HEIF(name) static const auto name##_fn = libheif().function<decltype(&name)>(#name)

// A context with the file read and its primary image's handle, both released on scope exit.
struct Primary {
  heif_context* ctx = nullptr;
  heif_image_handle* handle = nullptr;
  std::string file;

  explicit Primary(const std::filesystem::path& path) : file(path.string()) {
    RSIBR_HEIF(heif_context_alloc);
    RSIBR_HEIF(heif_context_read_from_file);
    RSIBR_HEIF(heif_context_get_primary_image_handle);
    ctx = heif_context_alloc_fn();
    if (!ctx) throw std::runtime_error(file + ": cannot allocate a HEIF context");
    check(heif_context_read_from_file_fn(ctx, file.c_str(), nullptr), "not a readable HEIF file");
    check(heif_context_get_primary_image_handle_fn(ctx, &handle), "no primary image");
  }
  ~Primary() {
    RSIBR_HEIF(heif_image_handle_release);
    RSIBR_HEIF(heif_context_free);
    if (handle) heif_image_handle_release_fn(handle);
    if (ctx) heif_context_free_fn(ctx);
  }
  Primary(const Primary&) = delete;
  Primary& operator=(const Primary&) = delete;

  void check(const heif_error& e, const char* what) const {
    if (e.code != heif_error_Ok)
      throw std::runtime_error(file + ": " + what + " (libheif: " + (e.message ? e.message : "no message") + ")");
  }
};

}  // namespace

bool is_heif_file(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext == ".heic" || ext == ".heif" || ext == ".hif";
}

cv::Mat read_heif_image(const std::filesystem::path& path) {
  RSIBR_HEIF(heif_image_handle_get_luma_bits_per_pixel);
  RSIBR_HEIF(heif_decode_image);
  RSIBR_HEIF(heif_image_get_width);
  RSIBR_HEIF(heif_image_get_height);
  RSIBR_HEIF(heif_image_get_plane_readonly);
  RSIBR_HEIF(heif_image_release);
  const Primary p(path);
  const int bits = heif_image_handle_get_luma_bits_per_pixel_fn(p.handle);
  const bool deep = bits > 8;
  heif_image* raw = nullptr;
  p.check(heif_decode_image_fn(p.handle, &raw, heif_colorspace_RGB,
                               deep ? heif_chroma_interleaved_RRGGBB_LE : heif_chroma_interleaved_RGB, nullptr),
          "cannot decode the image");
  const std::unique_ptr<heif_image, void (*)(heif_image*)> img(raw, [](heif_image* i) { heif_image_release_fn(i); });
  const int w = heif_image_get_width_fn(img.get(), heif_channel_interleaved),
            h = heif_image_get_height_fn(img.get(), heif_channel_interleaved);
  int stride = 0;
  const uint8_t* data = heif_image_get_plane_readonly_fn(img.get(), heif_channel_interleaved, &stride);
  if (!data || w <= 0 || h <= 0) throw std::runtime_error(p.file + ": the decoded image has no pixels");
  cv::Mat rgb;
  if (deep) {
    // Little-endian codes of `bits` bits in 16-bit words, scaled to 16 bits (a 10-bit 1023 is 65535).
    rgb.create(h, w, CV_16UC3);
    const double scale = 65535.0 / double((1 << std::min(bits, 16)) - 1);
    for (int y = 0; y < h; ++y) {
      const uint8_t* row = data + std::size_t(y) * std::size_t(stride);
      auto* out = rgb.ptr<uint16_t>(y);
      for (int i = 0; i < 3 * w; ++i)
        out[i] = cv::saturate_cast<uint16_t>((row[2 * i] | (row[2 * i + 1] << 8)) * scale + 0.5);
    }
  } else {
    rgb.create(h, w, CV_8UC3);
    for (int y = 0; y < h; ++y)
      std::memcpy(rgb.ptr(y), data + std::size_t(y) * std::size_t(stride), std::size_t(3 * w));
  }
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  return bgr;
}

std::vector<unsigned char> heif_exif(const std::filesystem::path& path) {
  RSIBR_HEIF(heif_image_handle_get_number_of_metadata_blocks);
  RSIBR_HEIF(heif_image_handle_get_list_of_metadata_block_IDs);
  RSIBR_HEIF(heif_image_handle_get_metadata_size);
  RSIBR_HEIF(heif_image_handle_get_metadata);
  const Primary p(path);
  if (heif_image_handle_get_number_of_metadata_blocks_fn(p.handle, "Exif") < 1) return {};
  heif_item_id id = 0;
  heif_image_handle_get_list_of_metadata_block_IDs_fn(p.handle, "Exif", &id, 1);
  std::vector<unsigned char> block(heif_image_handle_get_metadata_size_fn(p.handle, id));
  if (block.size() < 4) return {};
  p.check(heif_image_handle_get_metadata_fn(p.handle, id, block.data()), "cannot read its Exif block");
  // The block starts with a 4-byte big-endian offset to the TIFF header (after an "Exif\0\0" that
  // some writers keep).
  const std::size_t offset =
      4 + ((std::size_t(block[0]) << 24) | (std::size_t(block[1]) << 16) | (std::size_t(block[2]) << 8) | block[3]);
  if (offset >= block.size()) throw std::runtime_error(p.file + ": its Exif block's TIFF offset is out of range");
  return std::vector<unsigned char>(block.begin() + long(offset), block.end());
}

}  // namespace rsibr
