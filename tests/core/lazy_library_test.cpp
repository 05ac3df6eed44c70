// core/lazy_library.h and formats/image_codecs.h: libraries opened on first use, with one clear error
// when they cannot be; the codecs round-trip through the library opened that way.
#include "core/lazy_library.h"

#include "formats/image_codecs.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace rsibr {
namespace {

std::string error_of(const LazyLibrary& library, const char* name) {
  try {
    library.symbol(name);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(LazyLibrary, AMissingLibraryIsAnErrorNamingItAndWhatItIsFor) {
  const LazyLibrary missing("librsibr_no_such_library.so.0", "testing the error");
  const std::string first = error_of(missing, "anything");
  EXPECT_NE(first.find("librsibr_no_such_library.so.0"), std::string::npos) << first;
  EXPECT_NE(first.find("testing the error"), std::string::npos) << first;
  EXPECT_EQ(error_of(missing, "anything"), first);  // said again on every use, not only the first
}

TEST(LazyLibrary, AMissingSymbolIsAnErrorNamingIt) {
  const LazyLibrary libc("libc.so.6", "testing the error");
  EXPECT_NE(libc.symbol("strlen"), nullptr);
  const std::string e = error_of(libc, "rsibr_no_such_symbol");
  EXPECT_NE(e.find("rsibr_no_such_symbol"), std::string::npos) << e;
  EXPECT_NE(e.find("libc.so.6"), std::string::npos) << e;
}

TEST(ImageCodecs, APngRoundTripsBitExactThroughTheLazilyOpenedCodecs) {
  cv::Mat image(7, 5, CV_16UC3);
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x) image.at<cv::Vec3w>(y, x) = cv::Vec3w(x * 9000, y * 9000 + 1, 65535 - x - y);
  std::vector<unsigned char> bytes;
  ASSERT_TRUE(encode_image(".png", image, bytes));
  const cv::Mat back = decode_image(bytes, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(back.type(), CV_16UC3);
  EXPECT_EQ(cv::norm(image, back, cv::NORM_INF), 0.0);
  EXPECT_TRUE(read_image("/nonexistent/rsibr.png", cv::IMREAD_UNCHANGED).empty());  // as cv::imread
}

}  // namespace
}  // namespace rsibr
