#include "formats/photo_set.h"

#include "formats/file_error.h"
#include "core/text.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

namespace fs = std::filesystem;
namespace rsibr {
namespace {

class PhotoSetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("rsibr_photoset_" + std::to_string(std::random_device{}()));
    fs::create_directories(dir_ / "v0");
    for (const char* f : {"v0/a.png", "v0/b.png", "board0.png", "cam.cameramodel"}) std::ofstream(dir_ / f) << "x";
  }
  void TearDown() override { fs::remove_all(dir_); }
  void write(const std::string& text) { std::ofstream(dir_ / "photoset.yaml") << text; }
  std::string load_error() {
    try {
      load_photo_set(dir_);
    } catch (const std::invalid_argument& e) {
      return e.what();
    } catch (const FileError& e) {  // a missing or unreadable file
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

const char* kGood = R"(rsibr_photoset: 1
camera: {name: test, model: cam.cameramodel, colour_space: lin_p3d65}
balls:
  - {name: chrome, kind: chrome, diameter_m: 0.1}
  - {name: grey, kind: grey}
views:
  - name: v0
    brackets:
      - {file: v0/a.png, exposure_s: 0.004, iso: 200, aperture: 8}
      - {file: v0/b.png}
chessboards: {corners: [10, 7], spacing_m: 0.03, files: [board0.png]}
)";

TEST_F(PhotoSetTest, ReadsEveryFieldAndResolvesPathsAgainstTheFolder) {
  write(kGood);
  const PhotoSet s = load_photo_set(dir_ / "photoset.yaml");
  EXPECT_EQ(s.camera_name, "test");
  EXPECT_EQ(s.camera_colour_space, "lin_p3d65");
  ASSERT_TRUE(s.camera_model);
  EXPECT_TRUE(fs::equivalent(*s.camera_model, dir_ / "cam.cameramodel"));
  ASSERT_EQ(s.balls.size(), 2u);
  EXPECT_EQ(s.balls[1].kind, BallKind::grey);
  EXPECT_FALSE(s.balls[1].diameter_m);
  ASSERT_EQ(s.views.size(), 1u);
  const PhotoView& v = s.view("v0");
  ASSERT_EQ(v.brackets.size(), 2u);
  EXPECT_TRUE(v.brackets[0].file.is_absolute());
  EXPECT_DOUBLE_EQ(*v.brackets[0].relative_exposure(), 0.004 * 2.0 / 64.0);
  EXPECT_FALSE(v.brackets[1].exposure_s);
  EXPECT_FALSE(v.brackets[1].relative_exposure());
  ASSERT_TRUE(s.chessboards);
  EXPECT_EQ(s.chessboards->corners_x, 10);
  EXPECT_EQ(s.chessboards->corners_y, 7);
}

TEST_F(PhotoSetTest, SaveThenLoadGivesTheSameSet) {
  write(kGood);
  const PhotoSet a = load_photo_set(dir_);
  fs::remove(dir_ / "photoset.yaml");
  save_photo_set(a);
  const PhotoSet b = load_photo_set(dir_);
  EXPECT_EQ(b.camera_name, a.camera_name);
  EXPECT_EQ(b.camera_colour_space, "lin_p3d65");
  EXPECT_EQ(*b.camera_model, *a.camera_model);
  ASSERT_EQ(b.views.size(), a.views.size());
  for (std::size_t i = 0; i < a.views[0].brackets.size(); ++i) {
    EXPECT_EQ(b.views[0].brackets[i].file, a.views[0].brackets[i].file);
    EXPECT_EQ(b.views[0].brackets[i].exposure_s, a.views[0].brackets[i].exposure_s);
    EXPECT_EQ(b.views[0].brackets[i].iso, a.views[0].brackets[i].iso);
    EXPECT_EQ(b.views[0].brackets[i].aperture, a.views[0].brackets[i].aperture);
  }
  EXPECT_EQ(b.balls[0].diameter_m, a.balls[0].diameter_m);
  EXPECT_EQ(b.chessboards->files, a.chessboards->files);
  std::ifstream in(dir_ / "photoset.yaml");
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  EXPECT_EQ(text.find(dir_.string()), std::string::npos) << "paths under the folder are written relative";
}

TEST_F(PhotoSetTest, ExposuresFrom1Over32000To60SecondsRoundTripExactly) {
  PhotoSet s;
  s.folder = dir_;
  PhotoView v{"v0", {}};
  for (double t : {1.0 / 32000, 1.0 / 3, 0.1, 60.0}) v.brackets.push_back({dir_ / "v0/a.png", t, {}, {}});
  s.views.push_back(v);
  save_photo_set(s);
  const PhotoSet r = load_photo_set(dir_);
  for (std::size_t i = 0; i < v.brackets.size(); ++i)
    EXPECT_EQ(*r.views[0].brackets[i].exposure_s, *v.brackets[i].exposure_s);
}

TEST_F(PhotoSetTest, BadInputNamesTheFileAndTheKey) {
  const std::string yaml = (dir_ / "photoset.yaml").string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"rsibr_photoset: 1\nviews: [{name: v0, brackets: [{file: v0/a.png, exposure: 1}]}]\n",
       "photoset.views[0].brackets[0].exposure: unknown key"},
      {"rsibr_photoset: 1\nviews: [{name: v0, brackets: [{file: v0/a.png, exposure_s: -1}]}]\n",
       "photoset.views[0].brackets[0].exposure_s: must be in (0,inf)"},
      {"rsibr_photoset: 1\nviews: [{name: v0, brackets: [{file: v0/missing.png}]}]\n",
       "photoset.views[0].brackets[0].file: no such file"},
      {"rsibr_photoset: 1\nviews: [{name: v0, brackets: [{file: v0/a.png}]}, {name: v0, brackets: [{file: v0/b.png}]}]\n",
       "photoset.views[1].name: duplicate view name 'v0'"},
      {"rsibr_photoset: 1\nviews: [{name: v0, brackets: []}]\n", "photoset.views[0].brackets: expected a non-empty"},
      {"rsibr_photoset: 2\nviews: [{name: v0, brackets: [{file: v0/a.png}]}]\n",
       "photoset.rsibr_photoset: unsupported"},
      {"rsibr_photoset: 1\nballs: [{name: b, kind: copper}]\nviews: [{name: v0, brackets: [{file: v0/a.png}]}]\n",
       "photoset.balls[0].kind: unknown value 'copper'"},
      {"rsibr_photoset: 1\nviews: [{name: v0, brackets: [{file: v0/a.png}]}]\nchessboards: {corners: [1, 7], spacing_m: 0.03, files: [board0.png]}\n",
       "photoset.chessboards.corners: expected whole numbers >= 2"},
      {"rsibr_photoset: 1\nviews: {name: v0\n", yaml + ":"},
  };
  for (const auto& [text, expected] : cases) {
    write(text);
    const std::string error = load_error();
    EXPECT_EQ(error.rfind(yaml, 0), 0u) << error;
    EXPECT_NE(error.find(expected), std::string::npos) << "expected '" << expected << "' in: " << error;
  }
}

TEST_F(PhotoSetTest, ViewAndBallNamesThatAreNotSafeFileNamesAreRefusedNamingTheFileTheKeyAndTheName) {
  const std::string yaml = (dir_ / "photoset.yaml").string();
  auto view_named = [](const std::string& name) {
    return "rsibr_photoset: 1\nviews: [{name: \"" + name + "\", brackets: [{file: v0/a.png}]}]\n";
  };
  const std::string long_name(10000, 'a');
  const std::vector<std::pair<std::string, std::string>> cases = {
      {view_named("../../esc/stolen"), "photoset.views[0].name: a name starting with '.'"},
      {view_named("v/../../x"), "photoset.views[0].name: a name containing a path separator '/'"},
      {view_named("/somewhere/escaped"), "photoset.views[0].name: a name starting with a path separator '/'"},
      {view_named("."), "photoset.views[0].name: a name that is a folder reference"},
      {view_named(".."), "photoset.views[0].name: a name that is a folder reference"},
      {view_named(".hidden"), "photoset.views[0].name: a name starting with '.'"},
      {view_named("-v"), "photoset.views[0].name: a name starting with '-'"},
      {view_named("a\\\\b"), "photoset.views[0].name: a name containing a path separator '\\'"},
      {view_named("tab\\there"), "photoset.views[0].name: a name containing a control character"},
      {view_named("caf\\xe9"), "photoset.views[0].name: a name containing a character that is not ASCII"},
      {view_named(long_name), "photoset.views[0].name: a name of 10000 characters (at most 64)"},
      {"rsibr_photoset: 1\nviews: [{name: North, brackets: [{file: v0/a.png}]}, {name: north, brackets: [{file: v0/b.png}]}]\n",
       "photoset.views[1].name: view name 'north' clashes with 'North' (names must differ in more than letter case)"},
      {"rsibr_photoset: 1\nballs: [{name: ../chrome, kind: chrome}]\nviews: [{name: v0, brackets: [{file: v0/a.png}]}]\n",
       "photoset.balls[0].name: a name starting with '.'"},
      {"rsibr_photoset: 1\nballs: [{name: Grey, kind: grey}, {name: grey, kind: grey}]\nviews: [{name: v0, brackets: [{file: v0/a.png}]}]\n",
       "photoset.balls[1].name: ball name 'grey' clashes with 'Grey'"},
  };
  for (const auto& [text, expected] : cases) {
    write(text);
    const std::string error = load_error();
    EXPECT_EQ(error.rfind(yaml, 0), 0u) << error;
    EXPECT_NE(error.find(expected), std::string::npos) << "expected '" << expected << "' in: " << error;
    EXPECT_EQ(error.find('\n'), std::string::npos) << "one line: " << error;
    EXPECT_LT(error.size(), yaml.size() + 200) << "the name is shortened in the message";
  }
}

TEST_F(PhotoSetTest, ACameraNameThatIsNotUtf8IsKeptWithItsBadBytesReplaced) {
  // A Latin-1 byte (0xE9) in the raw file: not UTF-8.
  write(
      "rsibr_photoset: 1\ncamera: {name: \"Caf\xE9"
      " cam\"}\nviews: [{name: v0, brackets: [{file: v0/a.png}]}]\n");
  const PhotoSet s = load_photo_set(dir_);
  EXPECT_TRUE(is_utf8(s.camera_name)) << s.camera_name;
  EXPECT_NE(s.camera_name.find("cam"), std::string::npos);
}

TEST_F(PhotoSetTest, AMissingFileIsAClearError) {
  fs::remove_all(dir_ / "photoset.yaml");
  EXPECT_NE(load_error().find("no such file"), std::string::npos);
}

}  // namespace
}  // namespace rsibr
