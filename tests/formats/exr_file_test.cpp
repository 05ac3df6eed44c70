// The one EXR layer: channels by name, parts, attribute types, half range, data windows, errors.
#include "formats/exr_file.h"

#include "core/bitwise_equal.h"
#include "core/test_data.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>

namespace rsibr {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

cv::Mat noise(int w, int h, int channels, unsigned seed) {
  cv::Mat m(h, w, CV_32FC(channels));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.f, 1e6f);
  for (int r = 0; r < h; ++r)
    for (int x = 0; x < w * channels; ++x) m.ptr<float>(r)[x] = u(rng);
  m.ptr<float>(0)[0] = std::numeric_limits<float>::denorm_min();
  m.ptr<float>(h - 1)[w * channels - 1] = std::numeric_limits<float>::max();
  return m;
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const FileError& e) {
    return e.what();
  }
  return "";
}

TEST(ExrFile, PartsChannelsAndEveryAttributeTypeRoundTripExactly) {
  TempDir dir;
  const std::string path = (dir.path() / "two.exr").string();
  const cv::Mat rgb = noise(13, 7, 3, 1), single = noise(13, 7, 1, 2), other = noise(5, 9, 2, 3);
  Mat3 m;
  m << 0.25, -0.5, 1, 2, 3, 4, -1e-3f, 1e3f, 0.125;
  ExrPartOut a;
  a.name = "first";
  a.channels = {{"R", rgb, 0}, {"G", rgb, 1}, {"B", rgb, 2}, {"extra", single, 0}};
  a.attributes = {{"rsibr.text", std::string("caf\xc3\xa9")},
                  {"rsibr.count", -7},
                  {"rsibr.v", Vec3(0.5, -2, 8)},
                  {"rsibr.m", m},
                  {"rsibr.list", std::vector<float>{1.5f, -2.f, 1e-20f}}};
  ExrPartOut b;
  b.name = "second";
  b.channels = {{"u", other, 1}, {"v", other, 0}};
  b.compression = ExrCompression::Piz;  // lossless too
  write_exr(path, {a, b});

  const ExrFileIn in(path);
  ASSERT_EQ(in.parts().size(), 2u);
  const ExrPartIn& p = in.parts()[0];
  EXPECT_EQ(p.name, "first");
  EXPECT_EQ(p.width, 13);
  EXPECT_EQ(p.height, 7);
  EXPECT_EQ(p.compression, "zip");
  EXPECT_FALSE(p.working_from_file);  // Rec.709 chromaticities are written and need no conversion
  EXPECT_TRUE(testing::bitwise_equal(in.read(0, {"R", "G", "B"}), rgb));
  EXPECT_TRUE(testing::bitwise_equal(in.read(0, {"extra"}), single));
  EXPECT_EQ(p.get<std::string>("rsibr.text"), std::string("caf\xc3\xa9"));
  EXPECT_EQ(p.get<int>("rsibr.count"), -7);
  EXPECT_EQ(p.get<Vec3>("rsibr.v"), Vec3(0.5, -2, 8));
  EXPECT_EQ(p.get<Mat3>("rsibr.m"), Mat3(m.cast<float>().cast<double>()));
  EXPECT_EQ(p.get<std::vector<float>>("rsibr.list"), (std::vector<float>{1.5f, -2.f, 1e-20f}));
  EXPECT_FALSE(p.get<int>("rsibr.text"));  // a present attribute of another type is absent for that type
  EXPECT_EQ(p.strings_with_prefix("rsibr.").size(), 1u);
  // Channels come back in the order asked, whatever order the file holds them in.
  const cv::Mat vu = in.read(1, {"v", "u"});
  EXPECT_TRUE(testing::bitwise_equal(vu, other));
  EXPECT_EQ(in.parts()[1].compression, "piz");
}

TEST(ExrFile, StridedAndRegionOfInterestImagesAreWrittenAsTheirPixels) {
  TempDir dir;
  const cv::Mat big = noise(40, 30, 4, 4);
  const cv::Mat roi = big(cv::Rect(3, 5, 17, 11));  // not continuous
  ASSERT_FALSE(roi.isContinuous());
  const std::string path = (dir.path() / "roi.exr").string();
  write_exr(path, {ExrPartOut{"", {{"A", roi, 3}, {"B", roi, 1}}, {}, ExrEnvmap::None, false}});
  const cv::Mat back = ExrFileIn(path).read(0, {"A", "B"});
  cv::Mat expect;
  const int from_to[] = {3, 0, 1, 1};
  expect.create(roi.size(), CV_32FC2);
  cv::mixChannels(&roi, 1, &expect, 1, from_to, 2);
  EXPECT_TRUE(testing::bitwise_equal(back, expect));
}

TEST(ExrFile, HalfKeepsTheLargestHalfAndRefusesBeyondItLeavingNoFile) {
  TempDir dir;
  cv::Mat px(2, 2, CV_32FC1, cv::Scalar(1.0f));
  px.at<float>(0, 0) = 65504.f;                                 // the largest half: kept exactly
  px.at<float>(1, 1) = std::numeric_limits<float>::infinity();  // Inf is representable: kept
  const std::string ok = (dir.path() / "ok.exr").string();
  write_exr(ok, {ExrPartOut{"", {{"Y", px, 0}}, {}, ExrEnvmap::None, true}});
  const ExrFileIn in(ok);
  EXPECT_EQ(in.parts()[0].channel_types, "Y:half");
  const cv::Mat back = in.read(0, {"Y"});
  EXPECT_EQ(back.at<float>(0, 0), 65504.f);
  EXPECT_TRUE(std::isinf(back.at<float>(1, 1)));
  px.at<float>(0, 1) = 65520.f;  // would round to Inf
  const std::string bad = (dir.path() / "bad.exr").string();
  const std::string msg = message_of([&] {
    write_exr(bad, {ExrPartOut{"", {{"Y", px, 0}}, {}, ExrEnvmap::None, true}});
  });
  EXPECT_EQ(msg.rfind(bad + ": value 65520 at pixel (1, 0) exceeds the half-float range", 0), 0u) << msg;
  EXPECT_FALSE(fs::exists(bad));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);  // only ok.exr
}

TEST(ExrFile, ADataWindowAwayFromTheOriginIsReadWhole) {
  TempDir dir;
  const std::string path = (dir.path() / "offset.exr").string();
  const cv::Mat px = noise(6, 4, 1, 5);
  {
    const Imath::Box2i dw({-3, 10}, {2, 13});
    Imf::Header h(Imath::Box2i({0, 0}, {20, 20}), dw);
    h.channels().insert("Z", Imf::Channel(Imf::FLOAT));
    Imf::FrameBuffer fb;
    fb.insert("Z", Imf::Slice::Make(Imf::FLOAT, px.data, dw, sizeof(float), sizeof(float) * 6));
    Imf::OutputFile out(path.c_str(), h);
    out.setFrameBuffer(fb);
    out.writePixels(4);
  }
  const ExrFileIn in(path);
  EXPECT_EQ(in.parts()[0].width, 6);
  EXPECT_EQ(in.parts()[0].height, 4);
  EXPECT_TRUE(testing::bitwise_equal(in.read(0, {"Z"}), px));
}

TEST(ExrFile, ErrorsNameTheFileAndSayWhatIsWrongInOneLine) {
  TempDir dir;
  const std::string missing = (dir.path() / "missing.exr").string();
  EXPECT_EQ(message_of([&] { ExrFileIn in(missing); }), missing + ": no such file");
  const std::string text = (dir.path() / "text.exr").string();
  std::ofstream(text) << "not an image\n";
  EXPECT_EQ(message_of([&] { ExrFileIn in(text); }), text + ": not an OpenEXR file");
  EXPECT_FALSE(looks_like_exr(text));
  EXPECT_FALSE(looks_like_exr(missing));

  const std::string one = (dir.path() / "one.exr").string();
  const cv::Mat px = noise(3, 3, 1, 6);
  write_exr(one, {ExrPartOut{"", {{"Y", px, 0}}, {}, ExrEnvmap::None, false}});
  EXPECT_TRUE(looks_like_exr(one));
  const std::string msg = message_of([&] { ExrFileIn(one).read(0, {"R"}); });
  EXPECT_EQ(msg, one + ": no channel R (it has: Y:float)");
  EXPECT_EQ(msg.find('\n'), std::string::npos);

  // A truncated file: the header reads, the pixels do not.
  const std::string cut = (dir.path() / "cut.exr").string();
  const cv::Mat big = noise(64, 64, 1, 7);
  write_exr(cut, {ExrPartOut{"", {{"Y", big, 0}}, {}, ExrEnvmap::None, false}});
  fs::resize_file(cut, fs::file_size(cut) / 2);
  const std::string cut_msg = message_of([&] { ExrFileIn(cut).read(0, {"Y"}); });
  EXPECT_EQ(cut_msg.rfind(cut + ": ", 0), 0u) << cut_msg;
  EXPECT_EQ(cut_msg.find('\n'), std::string::npos) << cut_msg;

  // A long attribute name is refused before anything is written.
  const std::string longname = (dir.path() / "long.exr").string();
  const std::string name(32, 'a');
  EXPECT_EQ(message_of([&] {
              write_exr(longname, {ExrPartOut{"", {{"Y", px, 0}}, {{name, 1}}, ExrEnvmap::None, false}});
            }),
            longname + ": attribute name '" + name + "' is longer than 31 characters");
  EXPECT_FALSE(fs::exists(longname));
}

TEST(FileError, KeepsFileWhereAndProblemApartAndLocatesFurtherIn) {
  const FileError e("maps.exr", "not a rotation", "rsibr.worldFromView");
  EXPECT_STREQ(e.what(), "maps.exr: rsibr.worldFromView: not a rotation");
  const FileError f = e.within("part 3");
  EXPECT_EQ(f.file(), "maps.exr");
  EXPECT_EQ(f.where(), "part 3: rsibr.worldFromView");
  EXPECT_EQ(f.problem(), "not a rotation");
  EXPECT_STREQ(f.what(), "maps.exr: part 3: rsibr.worldFromView: not a rotation");
  EXPECT_STREQ(FileError("a.yaml", "no such file").what(), "a.yaml: no such file");
  // with_file: plain exceptions gain the file once, FileErrors pass unchanged, lines are folded.
  EXPECT_EQ(message_of([] { with_file("x.exr", [] { throw std::logic_error("two\nlines"); }); }), "x.exr: two lines");
  EXPECT_EQ(message_of([&] { with_file("y.exr", [&] { throw f; }); }), f.what());
}

}  // namespace
}  // namespace rsibr
