// Environment-map I/O: OpenEXR round trips, layout detection, channels by name, colour, errors.
#include "formats/exr_io.h"

#include "core/colour.h"
#include "core/bitwise_equal.h"
#include "core/test_data.h"
#include "formats/image_codecs.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfChromaticitiesAttribute.h>
#include <OpenEXR/ImfEnvmapAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <Imath/half.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <unistd.h>

namespace rsibr {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

cv::Mat random_pixels(int w, int h, int channels, std::mt19937& rng) {
  cv::Mat m(h, w, CV_32FC(channels));
  std::uniform_real_distribution<float> u(-2.f, 50.f);
  float* p = m.ptr<float>();
  const std::size_t n = std::size_t(w) * h * channels;
  for (std::size_t i = 0; i < n; ++i) p[i] = u(rng);
  // Extremes a float32 file must keep exactly.
  p[0] = 1e9f;
  p[1] = 1e-30f;
  p[2] = 0.f;
  p[3] = -3.5f;
  p[n - 1] = -0.f;
  p[n - 2] = std::numeric_limits<float>::denorm_min();
  p[n / 2] = std::numeric_limits<float>::max();
  return m;
}

// Writes a float EXR with the raw OpenEXR API: the named channels (interleaved in `pixels`, in
// that order) and whatever the caller put in the header.
void write_raw_exr(const std::string& path, const cv::Mat& pixels, const std::vector<std::string>& names,
                   Imf::Header header) {
  ASSERT_EQ(int(names.size()), pixels.channels());
  const int W = pixels.cols, H = pixels.rows, ch = pixels.channels();
  header.dataWindow() = header.displayWindow() = Imath::Box2i({0, 0}, {W - 1, H - 1});
  for (const auto& n : names) header.channels().insert(n, Imf::Channel(Imf::FLOAT));
  Imf::FrameBuffer fb;
  char* base = reinterpret_cast<char*>(const_cast<uchar*>(pixels.data));
  for (int k = 0; k < ch; ++k)
    fb.insert(names[k], Imf::Slice(Imf::FLOAT, base + k * sizeof(float), ch * sizeof(float),
                                   ch * sizeof(float) * std::size_t(W)));
  Imf::OutputFile out(path.c_str(), header);
  out.setFrameBuffer(fb);
  out.writePixels(H);
}

void write_raw_exr(const std::string& path, const cv::Mat& pixels, const std::vector<std::string>& names) {
  write_raw_exr(path, pixels, names, Imf::Header(pixels.cols, pixels.rows));
}

TEST(ExrIo, EnvironmentRoundTripIsBitExact) {
  TempDir dir;
  std::mt19937 rng(7);
  const std::vector<Layout> layouts = {Layout(LayoutKind::LatLong, 64, 32), Layout::with_size(LayoutKind::Cube, 8),
                                       Layout::with_size(LayoutKind::Octahedral, 16),
                                       Layout::with_size(LayoutKind::Sphere, 20), Layout(LayoutKind::Sphere, 17, 11)};
  for (const Layout& layout : layouts) {
    for (int channels : {3, 4}) {
      SCOPED_TRACE(to_string(layout.kind()) + " " + std::to_string(layout.width()) + "x" +
                   std::to_string(layout.height()) + " channels " + std::to_string(channels));
      EnvMap map;
      map.layout = layout;
      map.pixels = random_pixels(layout.width(), layout.height(), channels, rng);
      map.attributes = {{"tool", "rsibr bake --seed 3"}, {"source", "multi\nline text, ünïcode"}, {"empty", ""}};
      const std::string path = dir.file("env_" + to_string(layout.kind()) + ".exr");
      write_environment(path, map);
      EnvReadReport report;
      const EnvMap back = read_environment(path, std::nullopt, &report);
      EXPECT_EQ(back.layout.kind(), layout.kind());
      EXPECT_EQ(back.layout, layout);
      if (channels == 3) {
        EXPECT_TRUE(testing::bitwise_equal(back.pixels, map.pixels));
      } else {
        // The reader returns RGB; the first three channels must be untouched.
        cv::Mat rgb;
        std::vector<cv::Mat> planes;
        cv::split(map.pixels, planes);
        planes.resize(3);
        cv::merge(planes, rgb);
        EXPECT_TRUE(testing::bitwise_equal(back.pixels, rgb));
      }
      EXPECT_EQ(back.attributes, map.attributes);
      EXPECT_FALSE(report.chromaticities_converted);
      EXPECT_EQ(report.format, "exr");
      EXPECT_EQ(report.layout_source, layout.kind() == LayoutKind::LatLong || layout.kind() == LayoutKind::Cube
                                          ? "envmap attribute"
                                          : "rsibr.layout attribute");
    }
  }
  // Only the written files remain: no temporary leftovers.
  for (const std::string& name : dir.entries()) EXPECT_EQ(name.find(".tmp"), std::string::npos) << name;
}

TEST(ExrIo, LayoutComesFromEnvmapAttributeThenRsibrLayoutThenHintThenShape) {
  TempDir dir;
  std::mt19937 rng(11);
  // Ours, square octahedral: rsibr.layout decides, no hint needed; a contradicting hint loses.
  {
    EnvMap map;
    map.layout = Layout::with_size(LayoutKind::Octahedral, 8);
    map.pixels = random_pixels(8, 8, 3, rng);
    const std::string path = dir.file("octa.exr");
    write_environment(path, map);
    EnvReadReport report;
    EXPECT_EQ(read_environment(path, std::nullopt, &report).layout.kind(), LayoutKind::Octahedral);
    EXPECT_EQ(report.layout_source, "rsibr.layout attribute");
    EXPECT_EQ(read_environment(path, LayoutKind::Sphere, &report).layout.kind(), LayoutKind::Octahedral);
    EXPECT_EQ(report.layout_source, "rsibr.layout attribute");
  }
  // Raw square image, no attributes: needs the hint.
  {
    const std::string path = dir.file("square.exr");
    write_raw_exr(path, random_pixels(8, 8, 3, rng), {"R", "G", "B"});
    EnvReadReport report;
    EXPECT_EQ(read_environment(path, LayoutKind::Sphere, &report).layout.kind(), LayoutKind::Sphere);
    EXPECT_EQ(report.layout_source, "--layout");
    EXPECT_EQ(read_environment(path, LayoutKind::Octahedral, &report).layout.kind(), LayoutKind::Octahedral);
    try {
      read_environment(path);
      ADD_FAILURE() << "a square image without attributes or hint was accepted";
    } catch (const std::runtime_error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("--layout"), std::string::npos) << msg;
      EXPECT_EQ(msg.rfind(path, 0), 0u) << msg;
    }
  }
  // Shape alone: 2:1 lat-long, 1:6 cube; a hint beats the shape.
  {
    const std::string ll = dir.file("ll.exr"), cube = dir.file("cube.exr");
    write_raw_exr(ll, random_pixels(16, 8, 3, rng), {"R", "G", "B"});
    write_raw_exr(cube, random_pixels(4, 24, 3, rng), {"R", "G", "B"});
    EnvReadReport report;
    EXPECT_EQ(read_environment(ll, std::nullopt, &report).layout.kind(), LayoutKind::LatLong);
    EXPECT_EQ(report.layout_source, "shape");
    EXPECT_EQ(read_environment(cube, std::nullopt, &report).layout.kind(), LayoutKind::Cube);
    EXPECT_EQ(report.layout_source, "shape");
    EXPECT_EQ(read_environment(cube, LayoutKind::LatLong, &report).layout.kind(), LayoutKind::LatLong);
    EXPECT_EQ(report.layout_source, "--layout");
    // ... but a bare image that is not square is no mirror ball, whatever the hint says.
    try {
      read_environment(ll, LayoutKind::Sphere, &report);
      ADD_FAILURE() << "a 16x8 image was read as a sphere map";
    } catch (const std::runtime_error& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind(ll, 0), 0u) << msg;
      EXPECT_NE(msg.find("must be square"), std::string::npos) << msg;
    }
  }
  // envmap beats rsibr.layout; rsibr.layout beats the hint and the shape.
  {
    const std::string path = dir.file("both.exr");
    Imf::Header h(4, 24);
    Imf::addEnvmap(h, Imf::ENVMAP_CUBE);
    h.insert("rsibr.layout", Imf::StringAttribute("latlong"));
    write_raw_exr(path, random_pixels(4, 24, 3, rng), {"R", "G", "B"}, h);
    EnvReadReport report;
    EXPECT_EQ(read_environment(path, LayoutKind::LatLong, &report).layout.kind(), LayoutKind::Cube);
    EXPECT_EQ(report.layout_source, "envmap attribute");

    const std::string path2 = dir.file("rsibr_only.exr");
    Imf::Header h2(16, 8);
    h2.insert("rsibr.layout", Imf::StringAttribute("sphere"));
    write_raw_exr(path2, random_pixels(16, 8, 3, rng), {"R", "G", "B"}, h2);
    EXPECT_EQ(read_environment(path2, LayoutKind::LatLong, &report).layout.kind(), LayoutKind::Sphere);
    EXPECT_EQ(report.layout_source, "rsibr.layout attribute");
  }
}

TEST(ExrIo, RealEnvironmentsReadWithChannelsByName) {
  const auto files = testing::real_environments();
  if (files.empty()) GTEST_SKIP() << testing::kNoAssets;
  for (const auto& file : files) {
    SCOPED_TRACE(file.string());
    EnvReadReport report;
    const EnvMap map = read_environment(file.string(), std::nullopt, &report);
    EXPECT_EQ(map.layout.kind(), LayoutKind::LatLong);
    EXPECT_EQ(map.layout.width(), 512);
    EXPECT_EQ(map.layout.height(), 256);
    EXPECT_EQ(map.pixels.type(), CV_32FC3);
    EXPECT_EQ(report.layout_source, "shape");
    EXPECT_EQ(report.format, "exr");
    EXPECT_NE(report.channels.find("R:half"), std::string::npos) << report.channels;
    EXPECT_NE(report.channels.find("G:half"), std::string::npos) << report.channels;
    EXPECT_NE(report.channels.find("B:half"), std::string::npos) << report.channels;
    EXPECT_NE(report.compression.find("dwab"), std::string::npos) << report.compression;

    // The channels straight from OpenEXR, by name.
    Imf::InputFile in(file.c_str());
    const Imath::Box2i dw = in.header().dataWindow();
    const int W = dw.max.x - dw.min.x + 1, H = dw.max.y - dw.min.y + 1;
    // The file stores B before G before R (alphabetical); a reader taking channels by position
    // would put B in R.
    std::vector<std::string> order;
    for (auto it = in.header().channels().begin(); it != in.header().channels().end(); ++it) order.push_back(it.name());
    ASSERT_GE(order.size(), 3u);
    EXPECT_EQ(order[0], "B");
    std::vector<float> planes[3];
    const char* names[3] = {"R", "G", "B"};
    Imf::FrameBuffer fb;
    for (int k = 0; k < 3; ++k) {
      planes[k].assign(std::size_t(W) * H, 0.f);
      fb.insert(names[k], Imf::Slice::Make(Imf::FLOAT, planes[k].data(), dw, sizeof(float), sizeof(float) * W));
    }
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    const bool converted = report.chromaticities_converted;
    EXPECT_FALSE(converted) << "real files carry no (or Rec.709) chromaticities";
    int differs_rb = 0;
    for (int i = 0; i < 64; ++i) {
      const int x = (i * 97) % W, y = (i * 37 + 5) % H;
      const cv::Vec3f p = map.pixels.at<cv::Vec3f>(y, x);
      const std::size_t j = std::size_t(y) * W + x;
      for (int k = 0; k < 3 && !converted; ++k) EXPECT_EQ(p[k], planes[k][j]) << names[k] << " at " << x << "," << y;
      differs_rb += planes[0][j] != planes[2][j];
    }
    EXPECT_GT(differs_rb, 0) << "R and B identical at every probe: the channel check would prove nothing";
  }
}

TEST(ExrIo, HalfOutputRefusesOverflowAndLeavesNoFile) {
  TempDir dir;
  EnvMap map;
  map.layout = Layout(LayoutKind::LatLong, 8, 4);
  map.pixels = cv::Mat(4, 8, CV_32FC3, cv::Scalar(0.5f, 0.25f, 1.f));
  map.pixels.at<cv::Vec3f>(2, 3)[1] = 7e4f;
  const std::string path = dir.file("sun.exr");
  try {
    write_environment(path, map, {.half = true});
    ADD_FAILURE() << "7e4 written as half";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(path, 0), 0u) << msg;
    EXPECT_NE(msg.find("half"), std::string::npos) << msg;
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_TRUE(dir.entries().empty()) << dir.entries().front();

  // Negative overflow too.
  map.pixels.at<cv::Vec3f>(2, 3)[1] = -7e4f;
  EXPECT_THROW(write_environment(path, map, {.half = true}), std::runtime_error);
  EXPECT_TRUE(dir.entries().empty());

  // In range: the nearest half, stored as half.
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-65504.f, 65504.f);
  float* p = map.pixels.ptr<float>();
  for (int i = 0; i < 8 * 4 * 3; ++i) p[i] = u(rng) * (i % 3 == 0 ? 1e-4f : 1.f);
  p[0] = 65504.f;
  p[1] = -65504.f;
  p[2] = 1e-7f;  // subnormal half
  p[5] = 1.0f / 3.0f;
  write_environment(path, map, {.half = true});
  EnvReadReport report;
  const EnvMap back = read_environment(path, std::nullopt, &report);
  EXPECT_NE(report.channels.find("R:half"), std::string::npos) << report.channels;
  const float* q = back.pixels.ptr<float>();
  for (int i = 0; i < 8 * 4 * 3; ++i) EXPECT_EQ(q[i], float(Imath::half(p[i]))) << i << " " << p[i];
  EXPECT_EQ(q[0], 65504.f);
  EXPECT_NE(q[5], p[5]);  // really half precision
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"sun.exr"});
}

TEST(ExrIo, ChromaticitiesAreConvertedToTheWorkingSpace) {
  TempDir dir;
  const Imf::Chromaticities ap0({0.7347f, 0.2653f}, {0.f, 1.f}, {0.0001f, -0.077f}, {0.32168f, 0.33767f});
  Imf::Header h(16, 8);
  Imf::addChromaticities(h, ap0);
  cv::Mat px(8, 16, CV_32FC3, cv::Scalar(1.f, 1.f, 1.f));
  px.at<cv::Vec3f>(3, 5) = cv::Vec3f(1.f, 0.f, 0.f);
  px.at<cv::Vec3f>(4, 6) = cv::Vec3f(0.f, 0.f, 2.f);
  const std::string path = dir.file("aces.exr");
  write_raw_exr(path, px, {"R", "G", "B"}, h);

  EnvReadReport report;
  const EnvMap map = read_environment(path, std::nullopt, &report);
  EXPECT_TRUE(report.chromaticities_converted);
  const cv::Vec3f white = map.pixels.at<cv::Vec3f>(0, 0);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(white[k], 1.f, 1e-4) << k;
  const Eigen::Matrix3d m = working_from_chromaticities(ap0);
  const Eigen::Vector3d red = m * Eigen::Vector3d(1, 0, 0);
  const Eigen::Vector3d blue = m * Eigen::Vector3d(0, 0, 2);
  const cv::Vec3f r = map.pixels.at<cv::Vec3f>(3, 5), b = map.pixels.at<cv::Vec3f>(4, 6);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(r[k], red[k], 1e-5) << k;
    EXPECT_NEAR(b[k], blue[k], 1e-5) << k;
  }
  // AP0 red is far outside Rec.709: the conversion must really change it.
  EXPECT_GT(std::abs(r[0] - 1.f) + std::abs(r[1]) + std::abs(r[2]), 0.1f);

  // Rec.709 chromaticities (our own files) are not converted.
  EnvMap ours;
  ours.layout = Layout(LayoutKind::LatLong, 16, 8);
  ours.pixels = px.clone();
  write_environment(dir.file("ours.exr"), ours);
  const EnvMap back = read_environment(dir.file("ours.exr"), std::nullopt, &report);
  EXPECT_FALSE(report.chromaticities_converted);
  EXPECT_TRUE(testing::bitwise_equal(back.pixels, px));
}

TEST(ExrIo, LuminanceOnlyFileIsReadAsGrey) {
  TempDir dir;
  cv::Mat y(8, 16, CV_32FC1);
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 16; ++c) y.at<float>(r, c) = 0.25f * float(r * 16 + c) + 1.f;
  const std::string path = dir.file("grey.exr");
  write_raw_exr(path, y, {"Y"});
  EnvReadReport report;
  const EnvMap map = read_environment(path, std::nullopt, &report);
  EXPECT_EQ(report.channels, "Y:float");
  ASSERT_EQ(map.pixels.type(), CV_32FC3);
  ASSERT_EQ(map.pixels.size(), y.size());
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 16; ++c) {
      const cv::Vec3f p = map.pixels.at<cv::Vec3f>(r, c);
      for (int k = 0; k < 3; ++k) EXPECT_EQ(p[k], y.at<float>(r, c)) << r << "," << c << " channel " << k;
    }
}

TEST(ExrIo, NoColourChannelsIsAClearError) {
  TempDir dir;
  const std::string path = dir.file("depth.exr");
  write_raw_exr(path, cv::Mat(8, 16, CV_32FC1, cv::Scalar(3.f)), {"Z"});
  try {
    read_environment(path);
    ADD_FAILURE() << "a Z-only file was accepted";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(path, 0), 0u) << msg;
    EXPECT_NE(msg.find("Z:float"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

TEST(ExrIo, RadianceHdrIsReadInRgbOrder) {
  TempDir dir;
  cv::Mat bgr(8, 16, CV_32FC3);
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 16; ++c)  // B, G, R distinct and spanning magnitudes
      bgr.at<cv::Vec3f>(r, c) = cv::Vec3f(0.1f + 0.01f * c, 2.f + r, 500.f + 10.f * c);
  const std::string path = dir.file("sky.hdr");
  ASSERT_TRUE(rsibr::write_image(path, bgr));
  EnvReadReport report;
  const EnvMap map = read_environment(path, std::nullopt, &report);
  EXPECT_EQ(report.format, "hdr");
  EXPECT_EQ(map.layout.kind(), LayoutKind::LatLong);
  EXPECT_EQ(report.layout_source, "shape");
  ASSERT_EQ(map.pixels.type(), CV_32FC3);
  ASSERT_EQ(map.pixels.size(), bgr.size());
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 16; ++c) {
      const cv::Vec3f in = bgr.at<cv::Vec3f>(r, c), out = map.pixels.at<cv::Vec3f>(r, c);
      // RGBE: the mantissas share the largest channel's exponent, so the error is ~1% of the max.
      const float tol = 0.01f * std::max({in[0], in[1], in[2]});
      EXPECT_NEAR(out[0], in[2], tol) << "R";
      EXPECT_NEAR(out[1], in[1], tol) << "G";
      EXPECT_NEAR(out[2], in[0], tol) << "B";
    }
  // A square .hdr needs the hint like a square EXR.
  ASSERT_TRUE(rsibr::write_image(dir.file("square.hdr"), cv::Mat(8, 8, CV_32FC3, cv::Scalar(1, 1, 1))));
  EXPECT_THROW(read_environment(dir.file("square.hdr")), std::runtime_error);
  EXPECT_EQ(read_environment(dir.file("square.hdr"), LayoutKind::Sphere).layout.kind(), LayoutKind::Sphere);
}

void expect_one_line_error(const std::string& path) {
  SCOPED_TRACE(path);
  try {
    read_environment(path);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(path + ":", 0), 0u) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    EXPECT_GT(msg.size(), path.size() + 3) << msg;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not a std::runtime_error: " << e.what();
  } catch (...) {
    ADD_FAILURE() << "not a std::exception";
  }
}

TEST(ExrIo, MissingTruncatedAndNonImageFilesGiveOneLineErrors) {
  TempDir dir;
  expect_one_line_error(dir.file("missing.exr"));
  expect_one_line_error(dir.path().string());  // a folder

  EnvMap map;
  map.layout = Layout(LayoutKind::LatLong, 64, 32);
  std::mt19937 rng(5);
  map.pixels = random_pixels(64, 32, 3, rng);
  const std::string good = dir.file("good.exr");
  write_environment(good, map);
  std::string bytes;
  {
    std::ifstream in(good, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  ASSERT_GT(bytes.size(), 1000u);
  for (std::size_t cut : {std::size_t(100), bytes.size() / 2, bytes.size() - 10}) {
    const std::string truncated = dir.file("truncated_" + std::to_string(cut) + ".exr");
    std::ofstream(truncated, std::ios::binary).write(bytes.data(), std::streamsize(cut));
    expect_one_line_error(truncated);
  }
  const std::string text = dir.file("notes.exr");
  std::ofstream(text) << "this is not an image\nsecond line\n";
  expect_one_line_error(text);
  const std::string text_hdr = dir.file("notes.hdr");
  std::ofstream(text_hdr) << "#?RADIANCE\ngarbage\n";
  expect_one_line_error(text_hdr);
  const std::string empty = dir.file("empty.exr");
  std::ofstream(empty).flush();
  expect_one_line_error(empty);
}

TEST(ExrIo, AttributeNamesOver31CharactersAreRejected) {
  TempDir dir;
  EnvMap map;
  map.layout = Layout(LayoutKind::LatLong, 8, 4);
  map.pixels = cv::Mat(4, 8, CV_32FC3, cv::Scalar(1, 2, 3));
  // "rsibr." + 25 characters = 31: allowed.
  map.attributes[std::string(25, 'k')] = "ok";
  const std::string path = dir.file("attrs.exr");
  write_environment(path, map);
  EXPECT_EQ(read_environment(path).attributes.at(std::string(25, 'k')), "ok");
  // 26 characters: 32 in all, refused, and the existing file is untouched.
  map.attributes[std::string(26, 'x')] = "too long";
  const auto before = fs::last_write_time(path);
  try {
    write_environment(path, map);
    ADD_FAILURE() << "a 32-character attribute name was written";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(path, 0), 0u) << msg;
    EXPECT_NE(msg.find(std::string(26, 'x')), std::string::npos) << msg;
  }
  EXPECT_EQ(fs::last_write_time(path), before);
  EXPECT_EQ(read_environment(path).attributes.count(std::string(26, 'x')), 0u);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"attrs.exr"});
}

TEST(ExrIo, NanAndInfAreCountedInTheReport) {
  TempDir dir;
  EnvMap map;
  map.layout = Layout(LayoutKind::LatLong, 8, 4);
  map.pixels = cv::Mat(4, 8, CV_32FC3, cv::Scalar(1, 2, 3));
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  map.pixels.at<cv::Vec3f>(0, 0) = cv::Vec3f(nan, inf, -inf);
  map.pixels.at<cv::Vec3f>(1, 2) = cv::Vec3f(nan, nan, -1.f);
  map.pixels.at<cv::Vec3f>(3, 7) = cv::Vec3f(inf, -2.f, -0.5f);
  const std::string path = dir.file("bad.exr");
  write_environment(path, map);
  EnvReadReport report;
  read_environment(path, std::nullopt, &report);
  EXPECT_EQ(report.texels.nan, 3);
  EXPECT_EQ(report.texels.inf, 3);
  EXPECT_EQ(report.texels.negative, 3);
  // Half output keeps NaN and Inf (they are not overflow) and the counts survive.
  write_environment(path, map, {.half = true});
  read_environment(path, std::nullopt, &report);
  EXPECT_EQ(report.texels.nan, 3);
  EXPECT_EQ(report.texels.inf, 3);
  EXPECT_EQ(report.texels.negative, 3);
  // A clean file counts nothing.
  map.pixels = cv::Mat(4, 8, CV_32FC3, cv::Scalar(1, 2, 3));
  write_environment(path, map);
  read_environment(path, std::nullopt, &report);
  EXPECT_EQ(report.texels.nan + report.texels.inf + report.texels.negative, 0);
}

}  // namespace
}  // namespace rsibr
