#include "formats/yaml_spec.h"

#include <gtest/gtest.h>

#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>

#include "error_message.h"

namespace rsibr {
namespace {

using test_support::error_of;

TEST(ParseYaml, AnAliasInsideItsOwnAnchorIsACycleNamedWithItsKeyPath) {
  for (const char* text : {"a: &x [1, *x]", "lobe: &l {type: ggx, inner: *l}", "&r {self: *r}"}) {
    const std::string e = error_of([&] { parse_yaml(text, "spec.yaml"); });
    EXPECT_EQ(e.rfind("spec.yaml: document", 0), 0u) << text << " -> " << e;
    EXPECT_NE(e.find("cycle"), std::string::npos) << e;
  }
}

TEST(ParseYaml, AliasesThatExpandToBillionsOfNodesAreRefused) {
  // Each level doubles the nodes: 2^40 with aliases expanded, 40 lines as text.
  std::string text = "l0: &l0 [x, x]\n";
  for (int i = 1; i <= 40; ++i)
    text += "l" + std::to_string(i) + ": &l" + std::to_string(i) + " [*l" + std::to_string(i - 1) + ", *l" +
            std::to_string(i - 1) + "]\n";
  const std::string e = error_of([&] { parse_yaml(text, "bomb.yaml"); });
  EXPECT_NE(e.find("bomb.yaml: more than"), std::string::npos) << e;
}

TEST(ParseYaml, NestingDeeperThanTheLimitIsRefusedAndShallowerIsKept) {
  const auto nested = [](int depth) {
    return std::string(std::size_t(depth), '[') + std::string(std::size_t(depth), ']');
  };
  EXPECT_NE(error_of([&] { parse_yaml(nested(kMaxYamlDepth + 1), "deep.yaml"); }).find("nested deeper than"),
            std::string::npos);
  EXPECT_EQ(error_of([&] { parse_yaml(nested(kMaxYamlDepth - 1), "deep.yaml"); }), "");
}

TEST(ParseYaml, AliasesThatDoNotLoopAreKept) {
  const YAML::Node n = parse_yaml("base: &b {type: ggx, roughness: 0.3}\nlobes: [*b, *b]\n", "ok.yaml");
  EXPECT_EQ(n["lobes"][1]["roughness"].as<double>(), 0.3);
}

TEST(ParseYaml, SyntaxErrorsNameTheLineAndColumn) {
  EXPECT_EQ(error_of([] { parse_yaml("a: [1, 2\nb: 3\n", "bad.yaml"); }).rfind("bad.yaml:", 0), 0u);
}

TEST(LoadYamlFile, AFifoOrAFolderIsRefusedWithoutReading) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("rsibr_yaml_" + std::to_string(std::random_device{}()));
  std::filesystem::create_directories(dir);
  const std::filesystem::path fifo = dir / "pipe.yaml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(error_of([&] { load_yaml_file(fifo); }).find("pipe.yaml: not a regular file"), std::string::npos);
  EXPECT_NE(error_of([&] { load_yaml_file(dir); }).find("is a folder"), std::string::npos);
  EXPECT_NE(error_of([&] { load_yaml_file(dir / "missing.yaml"); }).find("no such file"), std::string::npos);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace rsibr
