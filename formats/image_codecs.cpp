#include "formats/image_codecs.h"

#include "formats/heif_image.h"
#include "core/lazy_library.h"

#include <opencv2/imgproc.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <type_traits>

namespace rsibr {
namespace {

// The build passes the SONAME of the opencv_imgcodecs it compiled against (CMakeLists.txt).
const LazyLibrary& codecs() {
  static const LazyLibrary library(RSIBR_IMGCODECS_SONAME, "reading and writing image files");
  return library;
}

// The mangled names below are those of libstdc++'s C++11 string ABI, the one Debian builds OpenCV with.
static_assert(_GLIBCXX_USE_CXX11_ABI, "formats/image_codecs.cpp: the mangled names assume the C++11 string ABI");
// Each signature is spelled once here; the static_cast makes the compiler check it against
// OpenCV's header (a mismatch with the mangled name below would be a crash, not an error).
using ReadFn = cv::Mat (*)(const cv::String&, int);
using EncodeFn = bool (*)(const cv::String&, cv::InputArray, std::vector<uchar>&, const std::vector<int>&);
using DecodeFn = cv::Mat (*)(cv::InputArray, int);
static_assert(std::is_same_v<decltype(static_cast<ReadFn>(&cv::imread)), ReadFn>);
static_assert(std::is_same_v<decltype(static_cast<EncodeFn>(&cv::imencode)), EncodeFn>);
static_assert(std::is_same_v<decltype(static_cast<DecodeFn>(&cv::imdecode)), DecodeFn>);

}  // namespace

cv::Mat read_image(const std::string& path, int flags) {
  if (is_heif_file(path)) {
    // libheif (formats/heif_image.h), converted as imread converts: 8 bits unless ANYDEPTH, grey
    // when asked.
    cv::Mat m = read_heif_image(path);
    if (flags != cv::IMREAD_UNCHANGED && !(flags & cv::IMREAD_ANYDEPTH) && m.depth() == CV_16U)
      m.convertTo(m, CV_8U, 1.0 / 257);
    if (flags == cv::IMREAD_GRAYSCALE) cv::cvtColor(m, m, cv::COLOR_BGR2GRAY);
    return m;
  }
  static const auto f =
      codecs().function<ReadFn>("_ZN2cv6imreadERKNSt7__cxx1112basic_stringIcSt11char_traitsIcESaIcEEEi");
  return f(path, flags);
}

// Encoded in memory, then written: the codec never sees the file, so a full disk is this
// function's `false`, not a codec's message on stderr (libpng prints its own).
bool write_image(const std::string& path, const cv::Mat& image, const std::vector<int>& params) {
  std::vector<unsigned char> bytes;
  const std::string extension = std::filesystem::path(path).extension().string();
  if (extension.empty() || !encode_image(extension, image, bytes, params)) return false;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  out.close();
  return bool(out);
}

bool encode_image(const std::string& extension, const cv::Mat& image, std::vector<unsigned char>& bytes,
                  const std::vector<int>& params) {
  static const auto f = codecs().function<EncodeFn>(
      "_ZN2cv8imencodeERKNSt7__cxx1112basic_stringIcSt11char_traitsIcESaIcEEERKNS_11_InputArrayERSt6vectorIhSaIhEERKSB_"
      "IiSaIiEE");
  return f(extension, image, bytes, params);
}

bool jpeg_is_complete(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  const std::vector<unsigned char> b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (b.size() < 4 || b[0] != 0xFF || b[1] != 0xD8) return false;
  std::size_t at = 2;
  while (at + 1 < b.size()) {
    if (b[at] != 0xFF) return false;              // segments follow each other without gaps
    while (at < b.size() && b[at] == 0xFF) ++at;  // fill bytes
    if (at >= b.size()) return false;
    const unsigned char marker = b[at++];
    if (marker == 0xD9) return false;                                    // the end before any scan
    if (marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) continue;  // no length
    if (at + 1 >= b.size()) return false;
    const std::size_t length = std::size_t(b[at]) << 8 | b[at + 1];
    if (length < 2) return false;
    if (marker == 0xDA) {
      for (std::size_t i = at + length; i + 1 < b.size(); ++i)
        if (b[i] == 0xFF && b[i + 1] == 0xD9) return true;
      return false;
    }
    at += length;
  }
  return false;
}

cv::Mat decode_image(const std::vector<unsigned char>& bytes, int flags) {
  static const auto f = codecs().function<DecodeFn>("_ZN2cv8imdecodeERKNS_11_InputArrayEi");
  return f(bytes, flags);
}

std::vector<unsigned char> png_bytes(const cv::Mat& image, const std::string& what) {
  std::vector<unsigned char> bytes;
  if (!encode_image(".png", image, bytes)) throw std::runtime_error(what + ": cannot encode the PNG");
  return bytes;
}

}  // namespace rsibr
