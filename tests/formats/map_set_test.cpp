// Map sets: multi-part OpenEXR round trip, validation, part naming and attributes.
#include "formats/map_set.h"

#include "formats/exr_io.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfChromaticitiesAttribute.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfMatrixAttribute.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfVecAttribute.h>
#include "core/bitwise_equal.h"
#include "core/test_data.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <unistd.h>

namespace rsibr {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::string part_name(int i) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "view.%03d", i);
  return buf;
}

// 12 views of the icosahedron, 33x33 random pixels, confidence on the odd (captured) views.
MapSet make_set(unsigned seed = 1, int size = 33) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.f, 100.f);
  MapSet set;
  const ViewSet vs = ViewSet::icosahedron();
  for (std::size_t i = 0; i < vs.views().size(); ++i) {
    MapView v;
    v.view = vs.views()[i];
    v.world_from_view = world_from_view_for(v.view);
    v.warp = i % 3 == 0 ? CentralDirection::Normal : CentralDirection::Mirror;
    v.source = i % 2 ? MapSource::Captured : MapSource::Computed;
    v.material = "brdf: ggx\nroughness: 0.3\n# view " + std::to_string(i) + "\n";
    v.attributes = {{"tool", "rsibr bake"}, {"seed", std::to_string(seed)}, {"note", "line 1\nline 2\t\"quoted\""}};
    v.rgb = cv::Mat(size, size, CV_32FC3);
    for (float *p = v.rgb.ptr<float>(), *e = p + size * size * 3; p != e; ++p) *p = u(rng);
    v.rgb.at<cv::Vec3f>(0, 0) = cv::Vec3f(1e9f, 1e-30f, -0.f);
    if (v.source == MapSource::Captured) {
      v.image = "IMG_" + std::to_string(4000 + i) + " é";
      v.confidence = cv::Mat(size, size, CV_32FC1);
      for (int r = 0; r < size; ++r)
        for (int c = 0; c < size; ++c) v.confidence.at<float>(r, c) = float((r * size + c + i) % 17) / 16.f;
    }
    set.views.push_back(std::move(v));
  }
  return set;
}

// The value a float32 attribute holds. Through a volatile: GCC 12.2's SLP vectorizer (-O2/-O3)
// was seen to fold double(float(x)) back to x in an inlined element-wise loop here.
double float_rounded(double x) {
  volatile float f = float(x);
  return double(f);
}
Vec3 float_rounded(const Vec3& v) { return Vec3(float_rounded(v.x()), float_rounded(v.y()), float_rounded(v.z())); }
Mat3 float_rounded(const Mat3& m) {
  Mat3 out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out(r, c) = float_rounded(m(r, c));
  return out;
}

TEST(MapSet, RoundTripKeepsEveryPixelAndAttribute) {
  TempDir dir;
  const MapSet set = make_set();
  const std::string path = dir.file("maps.exr");
  write_map_set(path, set);
  const MapSet back = read_map_set(path);
  ASSERT_EQ(back.views.size(), set.views.size());
  EXPECT_EQ(back.width(), 33);
  EXPECT_EQ(back.height(), 33);
  for (std::size_t i = 0; i < set.views.size(); ++i) {
    SCOPED_TRACE("view " + std::to_string(i));
    const MapView &a = set.views[i], &b = back.views[i];
    EXPECT_TRUE(testing::bitwise_equal(a.rgb, b.rgb));
    EXPECT_EQ(a.confidence.empty(), b.confidence.empty());
    if (!a.confidence.empty()) {
      EXPECT_TRUE(testing::bitwise_equal(a.confidence, b.confidence));
    }
    EXPECT_EQ(b.view, float_rounded(a.view));
    EXPECT_EQ(b.world_from_view, float_rounded(a.world_from_view));
    // Not transposed: the third column is the view.
    EXPECT_EQ(Vec3(b.world_from_view.col(2)), b.view);
    EXPECT_EQ(a.warp, b.warp);
    EXPECT_EQ(a.source, b.source);
    EXPECT_EQ(a.material, b.material);
    EXPECT_EQ(a.image, b.image);
    EXPECT_EQ(a.attributes, b.attributes);
  }
  // Determinism: writing what was read gives the same bytes, and so does writing the original again.
  const std::string again = dir.file("again.exr"), twice = dir.file("twice.exr");
  write_map_set(again, back);
  write_map_set(twice, set);
  const std::string bytes = read_bytes(path);
  EXPECT_FALSE(bytes.empty());
  EXPECT_TRUE(bytes == read_bytes(again));
  EXPECT_TRUE(bytes == read_bytes(twice));
  // Overwriting an existing file works and leaves no temporaries.
  write_map_set(path, back);
  EXPECT_TRUE(bytes == read_bytes(path));
  EXPECT_EQ(dir.entries(), (std::vector<std::string>{"again.exr", "maps.exr", "twice.exr"}));
}

TEST(MapSet, ViewSetIsRecomputedFromTheViews) {
  TempDir dir;
  const std::string path = dir.file("maps.exr");
  write_map_set(path, make_set(2, 4));
  const MapSet back = read_map_set(path);
  const ViewSet vs = back.view_set();
  EXPECT_EQ(vs.views().size(), 12u);
  EXPECT_EQ(vs.triangles().size(), 20u);
  EXPECT_TRUE(vs.surrounds());
  EXPECT_EQ(vs.triangles(), ViewSet::icosahedron().triangles());
}

// Expects validate() to throw std::invalid_argument and write_map_set a std::runtime_error, both
// naming `part` and containing `words`, with no file left behind.
void expect_rejected(const MapSet& set, const std::string& part, const std::string& words, const TempDir& dir) {
  SCOPED_TRACE(part + " / " + words);
  try {
    validate(set);
    ADD_FAILURE() << "validate accepted it";
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(part), std::string::npos) << msg;
    EXPECT_NE(msg.find(words), std::string::npos) << msg;
  }
  const std::string path = dir.file("bad.exr");
  try {
    write_map_set(path, set);
    ADD_FAILURE() << "write_map_set accepted it";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(path + ":", 0), 0u) << msg;
    EXPECT_NE(msg.find(part), std::string::npos) << msg;
    EXPECT_NE(msg.find(words), std::string::npos) << msg;
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_TRUE(dir.entries().empty()) << dir.entries().front();
}

TEST(MapSet, ValidationRejectsBadSets) {
  TempDir dir;
  const MapSet good = make_set(3, 4);
  EXPECT_NO_THROW(validate(good));

  {
    MapSet empty;
    EXPECT_THROW(validate(empty), std::invalid_argument);
    EXPECT_THROW(write_map_set(dir.file("bad.exr"), empty), std::runtime_error);
    EXPECT_TRUE(dir.entries().empty());
  }
  const std::vector<std::tuple<std::string, std::string, std::function<void(MapView&)>>> cases = {
      {"view.005", "size", [](MapView& v) { v.rgb = cv::Mat(5, 4, CV_32FC3, cv::Scalar(1, 1, 1)); }},
      {"view.004", "pixels", [](MapView& v) { v.rgb = cv::Mat(4, 4, CV_8UC3, cv::Scalar(1, 1, 1)); }},
      {"view.003", "confidence", [](MapView& v) { v.confidence = cv::Mat(3, 4, CV_32FC1, cv::Scalar(1)); }},
      {"view.002", "unit",
       [](MapView& v) {
         v.view *= 1.01;
         v.world_from_view.col(2) = v.view;
       }},
      {"view.007", "rotation", [](MapView& v) { v.world_from_view.col(0) *= 1.1; }},
      {"view.008", "rotation", [](MapView& v) { v.world_from_view.col(0) *= -1.0; }},  // reflection
      {"view.009", "third column", [](MapView& v) { v.world_from_view = world_from_view_for(-v.view); }},
      {"view.010", "third column", [](MapView& v) { v.world_from_view.transposeInPlace(); }},
      {"view.011", "reserved", [](MapView& v) { v.attributes["view"] = "x"; }},
      {"view.000", "reserved", [](MapView& v) { v.attributes["material"] = "x"; }},
      {"view.001", "reserved", [](MapView& v) { v.attributes["image"] = "x"; }},
      {"view.011", "31", [](MapView& v) { v.attributes[std::string(26, 'a')] = "x"; }},
  };
  for (const auto& [part, words, mutate] : cases) {
    MapSet bad = good;
    const int i = std::stoi(part.substr(5));
    bad.views[i].rgb = good.views[i].rgb.clone();
    mutate(bad.views[i]);
    expect_rejected(bad, part, words, dir);
  }
  {
    MapSet bad = good;
    bad.views[4].view = Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 1);
    expect_rejected(bad, "view.004", "unit", dir);
  }
  // 25 characters after "rsibr." is the longest allowed name.
  MapSet ok = good;
  ok.views[11].attributes[std::string(25, 'a')] = "x";
  EXPECT_NO_THROW(validate(ok));
  // A failed write over an existing file keeps the old file.
  const std::string path = dir.file("keep.exr");
  write_map_set(path, good);
  const std::string bytes = read_bytes(path);
  MapSet bad = good;
  bad.views[1].world_from_view.col(0) *= 1.1;
  EXPECT_THROW(write_map_set(path, bad), std::runtime_error);
  EXPECT_TRUE(bytes == read_bytes(path));
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.exr"});
}

TEST(MapSet, ReadingANonMapSetFileIsAClearError) {
  TempDir dir;
  EnvMap env;
  env.layout = Layout(LayoutKind::LatLong, 16, 8);
  env.pixels = cv::Mat(8, 16, CV_32FC3, cv::Scalar(1, 2, 3));
  const std::string plain = dir.file("plain.exr");
  write_environment(plain, env);
  try {
    read_map_set(plain);
    ADD_FAILURE() << "a plain environment was read as a map set";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(plain + ":", 0), 0u) << msg;
    EXPECT_NE(msg.find("view.000"), std::string::npos) << msg;
  }
  EXPECT_FALSE(is_map_set_file(plain));
  EXPECT_FALSE(is_map_set_file(dir.file("missing.exr")));
  std::ofstream(dir.file("text.exr")) << "not an image\n";
  EXPECT_FALSE(is_map_set_file(dir.file("text.exr")));
  EXPECT_THROW(read_map_set(dir.file("text.exr")), std::runtime_error);
  EXPECT_THROW(read_map_set(dir.file("missing.exr")), std::runtime_error);

  const std::string maps = dir.file("maps.exr");
  write_map_set(maps, make_set(4, 4));
  EXPECT_TRUE(is_map_set_file(maps));
}

TEST(MapSet, AHeaderAttributeClaimingMoreBytesThanTheFileIsRefusedBeforeOpenExrAllocatesIt) {
  // OpenEXR 3.1 allocated (and cleared) the claimed size of a string attribute before finding the
  // file too short: 2 GB for a 4 KB file (fuzz/regressions/fuzz_map_set/).
  TempDir dir;
  const std::string maps = dir.file("maps.exr");
  write_map_set(maps, make_set(4, 4));
  std::ifstream in(maps, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), {});
  const std::string key = std::string("rsibr.warp") + '\0' + "string" + '\0';
  const std::size_t at = bytes.find(key);
  ASSERT_NE(at, std::string::npos);
  for (int k = 0; k < 4; ++k) bytes[at + key.size() + std::size_t(k)] = k == 3 ? '\x7f' : '\xff';  // 2^31 - 1
  const std::string bad = dir.file("claims-2gb.exr");
  std::ofstream(bad, std::ios::binary) << bytes;
  try {
    read_map_set(bad);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind(bad + ": ", 0), 0u) << msg;
    EXPECT_NE(msg.find("'rsibr.warp' claims 2147483647 bytes"), std::string::npos) << msg;
    EXPECT_EQ(msg.find(bad, 1), std::string::npos) << "the path is named once: " << msg;
  }
  EXPECT_FALSE(is_map_set_file(bad));
}

// The warp and the source are enums in memory; a file with any other value is refused when read,
// naming the file, the part and the attribute.
TEST(MapSet, AnUnknownWarpOrSourceInAFileIsAClearError) {
  TempDir dir;
  const std::string maps = dir.file("maps.exr");
  MapSet set = make_set(4, 4);
  for (MapView& v : set.views) {
    v.warp = CentralDirection::Mirror;
    v.source = MapSource::Computed;
    v.confidence.release();
  }
  write_map_set(maps, set);
  const std::string good = read_bytes(maps);
  for (const auto& [attribute, value, replacement] :
       {std::tuple{"rsibr.warp", "mirror", "mirrox"}, std::tuple{"rsibr.source", "computed", "guessed!"}}) {
    std::string bytes = good;
    const std::string key = std::string(attribute) + '\0' + "string" + '\0';
    const std::size_t at = bytes.find(key);
    ASSERT_NE(at, std::string::npos);
    const std::size_t value_at = at + key.size() + 4;  // after the 4-byte size
    ASSERT_EQ(bytes.compare(value_at, std::strlen(value), value), 0) << attribute;
    bytes.replace(value_at, std::strlen(value), replacement);  // same length
    const std::string bad = dir.file(std::string("bad-") + attribute + ".exr");
    std::ofstream(bad, std::ios::binary) << bytes;
    try {
      read_map_set(bad);
      ADD_FAILURE() << attribute << ": no error";
    } catch (const std::runtime_error& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind(bad + ": ", 0), 0u) << msg;
      EXPECT_NE(msg.find(std::string(attribute) + ": '" + replacement + "' is neither"), std::string::npos) << msg;
      EXPECT_NE(msg.find("part 0"), std::string::npos) << msg;
    }
  }
}

TEST(MapSet, PartsAreNamedInOrder) {
  TempDir dir;
  const MapSet set = make_set(5, 6);
  const std::string path = dir.file("maps.exr");
  write_map_set(path, set);
  Imf::MultiPartInputFile file(path.c_str());
  ASSERT_EQ(file.parts(), int(set.views.size()));
  for (int i = 0; i < file.parts(); ++i) {
    SCOPED_TRACE(part_name(i));
    const Imf::Header& h = file.header(i);
    const MapView& v = set.views[std::size_t(i)];
    ASSERT_TRUE(h.hasName());
    EXPECT_EQ(h.name(), part_name(i));
    const auto* view = h.findTypedAttribute<Imf::V3fAttribute>("rsibr.view");
    const auto* T = h.findTypedAttribute<Imf::M33fAttribute>("rsibr.worldFromView");
    const auto* warp = h.findTypedAttribute<Imf::StringAttribute>("rsibr.warp");
    const auto* source = h.findTypedAttribute<Imf::StringAttribute>("rsibr.source");
    const auto* material = h.findTypedAttribute<Imf::StringAttribute>("rsibr.material");
    ASSERT_TRUE(view && T && warp && source && material);
    EXPECT_EQ(view->value(), Imath::V3f(float(v.view.x()), float(v.view.y()), float(v.view.z())));
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) EXPECT_EQ(T->value()[r][c], float(v.world_from_view(r, c))) << r << c;
    EXPECT_EQ(warp->value(), to_string(v.warp));
    EXPECT_EQ(source->value(), to_string(v.source));
    EXPECT_EQ(material->value(), v.material);
    for (const auto& [key, value] : v.attributes) {
      const auto* a = h.findTypedAttribute<Imf::StringAttribute>("rsibr." + key);
      ASSERT_TRUE(a) << key;
      EXPECT_EQ(a->value(), value);
    }
    ASSERT_TRUE(Imf::hasChromaticities(h));
    const Imf::Chromaticities c = Imf::chromaticities(h), rec709;
    EXPECT_EQ(c.red, rec709.red);
    EXPECT_EQ(c.green, rec709.green);
    EXPECT_EQ(c.blue, rec709.blue);
    EXPECT_EQ(c.white, rec709.white);
    for (auto it = h.begin(); it != h.end(); ++it) EXPECT_LT(std::strlen(it.name()), 32u) << it.name();
    // Channels: R, G, B float, and confidence only on captured views.
    for (const char* name : {"R", "G", "B"}) {
      const Imf::Channel* ch = h.channels().findChannel(name);
      ASSERT_TRUE(ch) << name;
      EXPECT_EQ(ch->type, Imf::FLOAT);
    }
    EXPECT_EQ(h.channels().findChannel("confidence") != nullptr, v.source == MapSource::Captured);
    int n = 0;
    for (auto it = h.channels().begin(); it != h.channels().end(); ++it) ++n;
    EXPECT_EQ(n, v.source == MapSource::Captured ? 4 : 3);
  }
}

}  // namespace
}  // namespace rsibr

namespace rsibr {
namespace {

TEST(MapSet, AlbedoTableRoundTripsAndMustBeSharedAndValid) {
  TempDir dir;
  MapSet set = make_set(3, 9);
  std::vector<float> table;
  for (int k = 0; k < 16; ++k)
    for (int c = 0; c < 3; ++c) table.push_back(0.04f + 0.9f * float(k) / 15.0f * float(c + 1) / 3.0f);
  for (MapView& v : set.views) v.albedo = table;
  const std::string path = dir.file("maps.exr");
  write_map_set(path, set);
  const MapSet back = read_map_set(path);
  for (const MapView& v : back.views) EXPECT_EQ(v.albedo, table);

  MapSet differs = set;
  differs.views[4].albedo[7] += 0.01f;
  EXPECT_THROW(validate(differs), std::invalid_argument);
  MapSet negative = set;
  for (MapView& v : negative.views) v.albedo[0] = -1.0f;
  EXPECT_THROW(validate(negative), std::invalid_argument);
  MapSet short_table = set;
  for (MapView& v : short_table.views) v.albedo.resize(3);
  EXPECT_THROW(validate(short_table), std::invalid_argument);
  EXPECT_FALSE(fs::exists(dir.file("bad.exr")));
  EXPECT_THROW(write_map_set(dir.file("bad.exr"), differs), std::runtime_error);
  EXPECT_FALSE(fs::exists(dir.file("bad.exr")));
}

}  // namespace
}  // namespace rsibr
