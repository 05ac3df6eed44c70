#include "formats/output_plan.h"

#include <gtest/gtest.h>

#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>

#include "error_message.h"

namespace fs = std::filesystem;
namespace rsibr {
namespace {

using test_support::error_of;

std::string contents_of(const fs::path& p) {
  std::ifstream in(p);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

class OutputPlanTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("rsibr_output_plan_" + std::to_string(std::random_device{}()));
    fs::create_directories(dir_ / "sub");
    std::ofstream(dir_ / "in.exr") << "input";
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::size_t entries() const {
    return std::size_t(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()));
  }
  fs::path dir_;
};

TEST_F(OutputPlanTest, CommittedOutputsAppearTogetherAndNothingElseRemains) {
  {
    OutputPlan plan({dir_ / "in.exr"});
    const std::string a = plan.file((dir_ / "out.txt").string()), j = plan.file((dir_ / "out.json").string());
    EXPECT_EQ(fs::path(a).parent_path(), dir_);
    EXPECT_EQ(fs::path(a).extension(), ".txt") << "writers that pick the format by the extension still can";
    std::ofstream(a) << "map";
    std::ofstream(j) << "{}";
    EXPECT_FALSE(fs::exists(dir_ / "out.txt")) << "nothing is in place before the commit";
    plan.commit();
  }
  EXPECT_EQ(contents_of(dir_ / "out.txt"), "map");
  EXPECT_EQ(contents_of(dir_ / "out.json"), "{}");
  EXPECT_EQ(entries(), 4u) << "in.exr, sub, out.txt, out.json and no temporary";
}

// What a full disk leaves when the writer did not notice: an empty or broken file. The commit
// checks every output first (formats/written_file_check.h) and renames none of them.
TEST_F(OutputPlanTest, ACommitWithABrokenOutputRenamesNothingAndNamesTheTarget) {
  {
    OutputPlan plan;
    std::ofstream(plan.file((dir_ / "fine.json").string())) << "{}";
    std::ofstream(plan.file((dir_ / "half.exr").string())) << "not an EXR";
    std::string e;
    try {
      plan.commit();
    } catch (const std::runtime_error& x) {
      e = x.what();
    }
    EXPECT_NE(e.find((dir_ / "half.exr").string() + ": cannot write"), std::string::npos) << e;
  }
  EXPECT_EQ(entries(), 2u) << "in.exr and sub only";
}

TEST_F(OutputPlanTest, AFailureBeforeTheCommitLeavesNothing) {
  {
    OutputPlan plan;
    std::ofstream(plan.file((dir_ / "out.exr").string())) << "half";
    plan.file((dir_ / "out.json").string());
    // ... the verb throws here ...
  }
  EXPECT_EQ(entries(), 2u);
}

TEST_F(OutputPlanTest, AnOutputThatIsAnInputIsRefusedByIdentityNotSpelling) {
  fs::create_hard_link(dir_ / "in.exr", dir_ / "hard.exr");
  fs::create_symlink(dir_ / "in.exr", dir_ / "link.exr");
  for (const fs::path& out : {dir_ / "in.exr", dir_ / "sub" / ".." / "in.exr", dir_ / "hard.exr", dir_ / "link.exr"}) {
    OutputPlan plan({dir_ / "in.exr"});
    EXPECT_NE(error_of([&] { plan.file(out.string()); }).find("output would overwrite the input"), std::string::npos)
        << out;
  }
  EXPECT_EQ(contents_of(dir_ / "in.exr"), "input");
}

TEST_F(OutputPlanTest, TwoOutputsThatAreOneFileAreRefused) {
  OutputPlan plan;
  plan.file((dir_ / "a.json").string());
  EXPECT_NE(error_of([&] { plan.file((dir_ / "sub" / ".." / "a.json").string()); }).find("named twice"),
            std::string::npos);
  plan.folder((dir_ / "pictures").string());
  EXPECT_NE(error_of([&] { plan.file((dir_ / "pictures").string()); }).find("named twice"), std::string::npos);
}

TEST_F(OutputPlanTest, MissingFoldersFoldersAndFifosAreRefusedBeforeAnyWork) {
  OutputPlan plan;
  EXPECT_NE(error_of([&] { plan.file((dir_ / "nofolder" / "a.json").string()); }).find("does not exist"),
            std::string::npos);
  EXPECT_NE(error_of([&] { plan.file((dir_ / "sub").string()); }).find("is a folder"), std::string::npos);
  ASSERT_EQ(::mkfifo((dir_ / "pipe.json").c_str(), 0600), 0);
  EXPECT_NE(error_of([&] { plan.file((dir_ / "pipe.json").string()); }).find("not a regular file"), std::string::npos);
  std::ofstream(dir_ / "file") << "x";
  EXPECT_NE(error_of([&] { plan.folder((dir_ / "file").string()); }).find("is not a folder"), std::string::npos);
  EXPECT_EQ(plan.file(""), "");
  EXPECT_EQ(plan.file("-"), "-");
}

TEST_F(OutputPlanTest, AnErrorAboutATemporaryNamesTheTargetEvenAfterThePlanIsGone) {
  std::string message;
  {
    OutputPlan out;
    const std::string tmp = out.file((dir_ / "map.exr").string());
    message = tmp + ": No space left on device (writing " + tmp + ")";
  }
  const std::string target = (dir_ / "map.exr").string();
  EXPECT_EQ(OutputPlan::naming_targets(message), target + ": No space left on device (writing " + target + ")");
  EXPECT_EQ(OutputPlan::naming_targets("unrelated: message"), "unrelated: message");
}

TEST_F(OutputPlanTest, ACommitOfAnOutputThatWasNeverWrittenIsAnError) {
  OutputPlan plan;
  plan.file((dir_ / "out.exr").string());
  EXPECT_THROW(plan.commit(), std::logic_error);
}

}  // namespace
}  // namespace rsibr
