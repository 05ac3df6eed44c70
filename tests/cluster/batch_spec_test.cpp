#include "cluster/batch_spec.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace rsibr::cluster {
namespace {

const std::vector<std::string> kVerbs{"bake", "batch", "process", "view"};

std::filesystem::path spec_file(const std::string& name, const std::string& text) {
  const auto p = std::filesystem::temp_directory_path() / ("rsibr_batch_spec_" + name + ".yaml");
  std::ofstream(p) << text;
  return p;
}

std::string error_of(const std::string& name, const std::string& text) {
  const auto p = spec_file(name, text);
  try {
    read_batch_spec(p, kVerbs);
  } catch (const std::invalid_argument& e) {
    std::filesystem::remove(p);
    return e.what();
  }
  std::filesystem::remove(p);
  return "";
}

TEST(BatchSpec, BothJobFormsReadWithDefaultNames) {
  const auto p =
      spec_file("forms", "jobs:\n  - name: a\n    args: [bake, a.exr, --res, 8]\n  - [process, shoot, --out, run]\n");
  const auto jobs = read_batch_spec(p, kVerbs);
  std::filesystem::remove(p);
  ASSERT_EQ(jobs.size(), 2u);
  EXPECT_EQ(jobs[0].name, "a");
  EXPECT_EQ(jobs[0].args, (std::vector<std::string>{"bake", "a.exr", "--res", "8"}));
  EXPECT_EQ(jobs[1].name, "job 2");
  EXPECT_EQ(jobs[1].args.front(), "process");
}

TEST(BatchSpec, BadSpecsNameTheFileAndThePlace) {
  EXPECT_NE(error_of("nojobs", "jobs: []\n").find("batch.jobs: must be a non-empty list"), std::string::npos);
  EXPECT_NE(error_of("key", "job: []\n").find("job"), std::string::npos);
  EXPECT_NE(error_of("verb", "jobs:\n  - [bakee, x]\n").find("batch.jobs[0]: 'bakee' is not a verb"),
            std::string::npos);
  EXPECT_NE(error_of("nested", "jobs:\n  - [batch, other.yaml]\n").find("cannot run in a batch"), std::string::npos);
  EXPECT_NE(error_of("view", "jobs:\n  - [view, maps.exr]\n").find("cannot run in a batch"), std::string::npos);
  EXPECT_NE(error_of("word", "jobs:\n  - [bake, [x]]\n").find("batch.jobs[0][1]: must be a word"), std::string::npos);
  EXPECT_NE(error_of("noargs", "jobs:\n  - name: a\n").find("batch.jobs[0].args"), std::string::npos);
  EXPECT_NE(error_of("twice", "jobs:\n  - {name: a, args: [bake]}\n  - {name: a, args: [bake]}\n")
                .find("a second job named 'a'"),
            std::string::npos);
  const std::string e = error_of("syntax", "jobs: [\n");
  EXPECT_NE(e.find("rsibr_batch_spec_syntax.yaml"), std::string::npos) << e;
}

TEST(BatchSpec, JobsGoRoundTheRanksEachExactlyOnce) {
  for (int jobs : {0, 1, 19, 20})
    for (int ranks : {1, 2, 3, 32}) {
      std::vector<int> seen(std::size_t(jobs), 0);
      for (int k = 0; k < ranks; ++k)
        for (int i : jobs_of_rank(jobs, k, ranks)) {
          EXPECT_EQ(i % ranks, k);
          ++seen[std::size_t(i)];
        }
      for (int s : seen) EXPECT_EQ(s, 1);
    }
  EXPECT_THROW(jobs_of_rank(3, 2, 2), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr::cluster
