// Resumability (pipeline/step_record.h): a step is stale exactly when its record, settings, inputs
// or outputs say so.
#include "pipeline/step_record.h"

#include "pipeline/code_version.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <thread>

namespace rsibr {
namespace {

namespace fs = std::filesystem;

struct StepRecordTest : ::testing::Test {
  fs::path dir = fs::temp_directory_path() / ("rsibr-step-" + std::to_string(::getpid()) + "-" +
                                              ::testing::UnitTest::GetInstance()->current_test_info()->name());
  void SetUp() override {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  void write(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }
  // Makes a file's mtime strictly later than another's, whatever the file system's resolution.
  void touch_later(const fs::path& p, const fs::path& than) {
    fs::last_write_time(p, fs::last_write_time(than) + std::chrono::seconds(2));
  }
  StepRecord record(const nlohmann::json& settings) {
    StepRecord r;
    r.step = "bake";
    r.settings = settings;
    r.inputs = {dir / "in.txt"};
    r.outputs = {dir / "out.txt"};
    r.seconds = 1.5;
    r.summary = {{"views", 3}};
    return r;
  }
};

TEST_F(StepRecordTest, FreshOutputsWithTheSameSettingsAreUpToDate) {
  write(dir / "in.txt", "a");
  write(dir / "out.txt", "b");
  touch_later(dir / "out.txt", dir / "in.txt");
  write_step_record(dir, record({{"samples", 64}}));
  EXPECT_EQ(step_stale_reason(dir, "bake", {{"samples", 64}}, {dir / "in.txt"}), "");
  const StepRecord back = read_step_record(dir, "bake");
  EXPECT_EQ(back.summary["views"], 3);
  EXPECT_DOUBLE_EQ(back.seconds, 1.5);
}

TEST_F(StepRecordTest, MissingRecordChangedSettingsTouchedInputOrDeletedOutputAreStale) {
  write(dir / "in.txt", "a");
  write(dir / "out.txt", "b");
  touch_later(dir / "out.txt", dir / "in.txt");
  EXPECT_EQ(step_stale_reason(dir, "bake", {{"samples", 64}}, {dir / "in.txt"}), "no record");
  write_step_record(dir, record({{"samples", 64}}));
  EXPECT_EQ(step_stale_reason(dir, "bake", {{"samples", 32}}, {dir / "in.txt"}), "settings changed");
  EXPECT_EQ(step_stale_reason(dir, "bake", {{"samples", 64}}, {dir / "in.txt", dir / "out.txt"}), "inputs changed");
  // An input rewritten (same size, later time) is a change.
  write(dir / "in.txt", "c");
  touch_later(dir / "in.txt", dir / "out.txt");
  EXPECT_NE(step_stale_reason(dir, "bake", {{"samples", 64}}, {dir / "in.txt"}).find("in.txt changed"),
            std::string::npos);
  write_step_record(dir, record({{"samples", 64}}));
  // A touched input with the same contents (a later mtime, the same bytes) is no change.
  touch_later(dir / "in.txt", dir / "out.txt");
  EXPECT_EQ(step_stale_reason(dir, "bake", {{"samples", 64}}, {dir / "in.txt"}), "");
  // An output replaced by other bytes of the same size (restored from a backup, say) is stale.
  write(dir / "out.txt", "x");
  touch_later(dir / "out.txt", dir / "in.txt");
  EXPECT_NE(step_stale_reason(dir, "bake", {{"samples", 64}}, {dir / "in.txt"}).find("out.txt changed"),
            std::string::npos);
  write(dir / "out.txt", "b");
  EXPECT_EQ(step_stale_reason(dir, "bake", {{"samples", 64}}, {dir / "in.txt"}), "");
  fs::remove(dir / "out.txt");
  EXPECT_NE(step_stale_reason(dir, "bake", {{"samples", 64}}, {dir / "in.txt"}).find("missing"), std::string::npos);
}

TEST_F(StepRecordTest, ARecordMadeByOtherCodeIsRedone) {
  write(dir / "in.txt", "a");
  write(dir / "out.txt", "b");
  touch_later(dir / "out.txt", dir / "in.txt");
  write_step_record(dir, record({{"samples", 64}}));
  ASSERT_EQ(step_stale_reason(dir, "bake", {{"samples", 64}}, {dir / "in.txt"}), "");
  const fs::path file = step_record_path(dir, "bake");
  nlohmann::json j;
  std::ifstream(file) >> j;
  EXPECT_EQ(j["code"], rsibr_code_version());
  EXPECT_EQ(j["rsibr_version"], RSIBR_VERSION);
  // Another build of the same version (its sources differ): redone.
  j["code"] = std::string(64, '0');
  std::ofstream(file) << j.dump();
  EXPECT_EQ(step_stale_reason(dir, "bake", {{"samples", 64}}, {dir / "in.txt"}),
            std::string("made by other code (rsibr ") + RSIBR_VERSION + ")");
  // A record of an rsibr that kept no code version: redone too.
  j.erase("code");
  j.erase("rsibr_version");
  std::ofstream(file) << j.dump();
  EXPECT_EQ(step_stale_reason(dir, "bake", {{"samples", 64}}, {dir / "in.txt"}), "made by other code (rsibr unknown)");
}

TEST(CodeVersion, IsTheHashOfTheSourcesThisBuildWasMadeFrom) {
  // Recomputed from the source tree now by the build's own script: a source that changed without
  // the version changing (a stale or hand-written version) fails here.
  const fs::path out = fs::temp_directory_path() / ("rsibr-code-version-" + std::to_string(::getpid()) + ".cpp");
  const std::string command = std::string("'") + RSIBR_CMAKE_COMMAND + "' -DROOT='" + RSIBR_SOURCE_DIR + "' -DOUT='" +
                              out.string() + "' -DFOLDERS=" + RSIBR_CODE_FOLDERS + " -P '" + RSIBR_SOURCE_DIR +
                              "/pipeline/code_version.cmake'";
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
  std::stringstream text;
  text << std::ifstream(out).rdbuf();
  fs::remove(out);
  const std::string version = rsibr_code_version();
  ASSERT_EQ(version.size(), 64u);
  EXPECT_EQ(version.find_first_not_of("0123456789abcdef"), std::string::npos) << version;
  EXPECT_NE(text.str().find('"' + version + '"'), std::string::npos) << text.str();
}

TEST_F(StepRecordTest, AMalformedRecordIsStaleAndReadingItNamesTheFile) {
  fs::create_directories(dir / "steps");
  write(dir / "steps" / "bake.json", "{not json");
  EXPECT_EQ(step_stale_reason(dir, "bake", {}, {}), "unreadable record");
  try {
    read_step_record(dir, "bake");
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bake.json"), std::string::npos);
  }
  EXPECT_THROW(file_stamp(dir / "nothere"), std::runtime_error);
}

// A run folder copied without its files' times (cp -r), with its photo folder moved elsewhere, is
// up to date: paths are relative to the run and photo folders, and contents are compared by size
// and SHA-256 when the times differ.
TEST_F(StepRecordTest, ACopiedRunFolderWithMovedPhotosIsUpToDate) {
  const fs::path run = dir / "run", photos = dir / "photos";
  fs::create_directories(run / "maps");
  fs::create_directories(photos / "v0");
  write(photos / "v0" / "b0.png", "photo bytes");
  write(run / "maps" / "m.exr", "map bytes");
  write(run / "camera.cameramodel", "lens");
  StepRecord r;
  r.step = "extract";
  r.inputs = {photos / "v0" / "b0.png", run / "camera.cameramodel"};
  r.outputs = {run / "maps" / "m.exr"};
  const RecordRoots roots{run, photos};
  write_step_record(run, r, roots);
  ASSERT_EQ(step_stale_reason(run, "extract", nlohmann::json::object(), r.inputs, roots), "");
  // Copy (new times: a copy made later) and move the photos.
  const fs::path run2 = dir / "elsewhere" / "run", photos2 = dir / "moved" / "photos";
  fs::create_directories(run2.parent_path());
  fs::create_directories(photos2.parent_path());
  fs::copy(run, run2, fs::copy_options::recursive);
  fs::rename(photos, photos2);
  for (const fs::path& p : {run2 / "maps" / "m.exr", run2 / "camera.cameramodel", photos2 / "v0" / "b0.png"})
    fs::last_write_time(p, fs::last_write_time(p) + std::chrono::seconds(7));
  const RecordRoots roots2{run2, photos2};
  const std::vector<fs::path> inputs2 = {photos2 / "v0" / "b0.png", run2 / "camera.cameramodel"};
  EXPECT_EQ(step_stale_reason(run2, "extract", nlohmann::json::object(), inputs2, roots2), "");
  const StepRecord back = read_step_record(run2, "extract", roots2);
  ASSERT_EQ(back.outputs.size(), 1u);
  EXPECT_EQ(back.outputs[0], fs::absolute(run2 / "maps" / "m.exr").lexically_normal());
  EXPECT_EQ(back.inputs[0], fs::absolute(photos2 / "v0" / "b0.png").lexically_normal());
  // The copy is independent: an edited input in it is a change there only.
  write(photos2 / "v0" / "b0.png", "other bytes");
  EXPECT_NE(step_stale_reason(run2, "extract", nlohmann::json::object(), inputs2, roots2).find("b0.png changed"),
            std::string::npos);
  // Another file in the input's place (another name) is a change even with the same contents.
  write(run2 / "lens2.cameramodel", "lens");
  write(photos2 / "v0" / "b0.png", "photo bytes");
  EXPECT_EQ(step_stale_reason(run2, "extract", nlohmann::json::object(),
                              {photos2 / "v0" / "b0.png", run2 / "lens2.cameramodel"}, roots2),
            (run2 / "lens2.cameramodel").string() + " changed");
}

TEST_F(StepRecordTest, AFailedStepLeavesItsErrorAndFindingsButNoRecordUntilItSucceeds) {
  write(dir / "in.txt", "input");
  write(dir / "out.txt", "output");
  const StepRecord r = record({{"k", 1}});
  write_failed_step_record(dir, r, "bake: the map is empty");
  const fs::path failed = failed_step_record_path(dir, "bake");
  ASSERT_TRUE(fs::exists(failed));
  std::ifstream in(failed);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["status"], "failed");
  EXPECT_EQ(j["error"], "bake: the map is empty");
  EXPECT_EQ(j["summary"]["views"], 3);
  // Never taken for the step's record.
  EXPECT_EQ(step_stale_reason(dir, "bake", {{"k", 1}}, r.inputs), "no record");
  write_step_record(dir, r);
  remove_failed_step_record(dir, "bake");
  EXPECT_FALSE(fs::exists(failed));
  EXPECT_EQ(step_stale_reason(dir, "bake", {{"k", 1}}, r.inputs), "");
  remove_failed_step_record(dir, "bake");  // none there: nothing happens
}

TEST_F(StepRecordTest, Sha256OfAKnownTextIsTheStandardDigest) {
  write(dir / "abc.txt", "abc");
  EXPECT_EQ(file_sha256(dir / "abc.txt"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  write(dir / "empty.txt", "");
  EXPECT_EQ(file_sha256(dir / "empty.txt"), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
}

}  // namespace
}  // namespace rsibr
