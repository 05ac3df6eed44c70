// Resumability (pipeline/step_record.h): a step is stale exactly when its record, settings, inputs
// or outputs say so.
#include "pipeline/step_record.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <fstream>
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
  EXPECT_NE(step_stale_reason(dir, "bake", {{"samples", 64}}, {dir / "in.txt"}).find("in.txt changed"), std::string::npos);
  write_step_record(dir, record({{"samples", 64}}));
  // The output older than its input (restored from a backup, say).
  touch_later(dir / "in.txt", dir / "out.txt");
  write_step_record(dir, record({{"samples", 64}}));
  EXPECT_NE(step_stale_reason(dir, "bake", {{"samples", 64}}, {dir / "in.txt"}).find("older than its inputs"),
            std::string::npos);
  touch_later(dir / "out.txt", dir / "in.txt");
  write_step_record(dir, record({{"samples", 64}}));
  EXPECT_EQ(step_stale_reason(dir, "bake", {{"samples", 64}}, {dir / "in.txt"}), "");
  fs::remove(dir / "out.txt");
  EXPECT_NE(step_stale_reason(dir, "bake", {{"samples", 64}}, {dir / "in.txt"}).find("missing"), std::string::npos);
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

}  // namespace
}  // namespace rsibr
