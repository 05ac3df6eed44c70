// HEIF/HEIC photos (phones' default format) through libheif, opened on first use (core/
// lazy_library.h: libheif brings its HEVC and AV1 codecs, which a command that reads no HEIF
// photo should not load). The primary image only (a burst's or a depth map's other images are
// not photos of the scene); its pixels as OpenCV would give them for a JPEG or a 16-bit TIFF.
#pragma once

#include <opencv2/core.hpp>

#include <filesystem>
#include <vector>

namespace rsibr {

// By extension: .heic, .heif, .hif (any case).
bool is_heif_file(const std::filesystem::path& path);

// The primary image, BGR: CV_8UC3 for 8-bit files, CV_16UC3 for deeper ones (10- and 12-bit codes
// scaled to the full 16-bit range, as a 16-bit TIFF holds them). Throws std::runtime_error("<file>:
// <problem>") when the file is not HEIF or cannot be decoded, or libheif is not installed.
cv::Mat read_heif_image(const std::filesystem::path& path);

// The primary image's Exif block as a TIFF stream (the header "II*\0" or "MM\0*" first, ready for
// exiv2's ExifParser), or empty when the file has none. Throws as read_heif_image.
std::vector<unsigned char> heif_exif(const std::filesystem::path& path);

}  // namespace rsibr
