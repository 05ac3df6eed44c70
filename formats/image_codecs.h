// Image files (PNG, JPEG, TIFF, ...) through OpenCV's codecs, loaded on first use
// (core/lazy_library.h says why). The same contracts as cv::imread, cv::imwrite, cv::imencode and
// cv::imdecode, whose flags and parameters (cv::IMREAD_*, cv::IMWRITE_*) they take; an empty
// Mat or `false` on failure, as there. Throws std::runtime_error only when the codec library
// cannot be loaded.
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>  // the flags only: the functions are looked up at run time

#include <string>
#include <vector>

namespace rsibr {

cv::Mat read_image(const std::string& path, int flags = cv::IMREAD_COLOR);
bool write_image(const std::string& path, const cv::Mat& image, const std::vector<int>& params = {});
bool encode_image(const std::string& extension, const cv::Mat& image, std::vector<unsigned char>& bytes,
                  const std::vector<int>& params = {});
cv::Mat decode_image(const std::vector<unsigned char>& bytes, int flags);
// A BGR(A) image as PNG bytes; throws std::runtime_error("<what>: cannot encode the PNG").
std::vector<unsigned char> png_bytes(const cv::Mat& image, const std::string& what);

// Whether the JPEG file at `path` holds its image data to the end-of-image marker. libjpeg decodes
// a truncated file without failing (grey rows where the data stopped, a warning on stderr), so a
// photo cut short by a copy would be merged as if it were whole. The segments are walked from the
// start of image to the first start of scan; an end-of-image marker must follow it (the entropy-
// coded data cannot hold one: 0xFF is stuffed there). Bytes after it (a phone's trailer) are
// allowed. False for a file that does not start as a JPEG or cannot be read.
bool jpeg_is_complete(const std::string& path);

}  // namespace rsibr
