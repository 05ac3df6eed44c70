// Strict reading of hand-written YAML specs (BRDFs, photo sets, synthetic scenes): every mapping
// names its allowed keys up front, so an unknown key, a missing one, a wrong type or an
// out-of-range value is an error naming the key path from the root, e.g.
// "photoset.views[2].brackets[0].exposure_s: must be in (0,inf), got -1".
// Errors are std::invalid_argument; callers prefix the file name.
#pragma once

#include "core/vec.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace rsibr {

[[noreturn]] void spec_fail(const std::string& path, const std::string& what);

// A number in the interval (lo|[lo, hi|hi]); *_open excludes the end. hi may be +inf.
double spec_in_range(double x, const std::string& path, double lo, bool lo_open, double hi, bool hi_open);

// A YAML number that is finite; `path` names it in errors.
double spec_number(const YAML::Node& v, const std::string& path);

// A mapping node with its key path; checks keys against the allowed set on construction.
class YamlMap {
 public:
  YamlMap(const YAML::Node& node, std::string path, const std::vector<std::string>& allowed);

  const std::string& path() const { return path_; }
  std::string at(const std::string& key) const { return path_ + "." + key; }
  bool has(const std::string& key) const;

  YAML::Node get(const std::string& key) const;  // missing or null -> error
  std::string string(const std::string& key) const;
  double number(const std::string& key) const;
  long integer(const std::string& key) const;  // a whole number
  bool boolean(const std::string& key) const;
  Vec3 vec3(const std::string& key) const;                    // a sequence of 3 numbers
  std::vector<double> numbers(const std::string& key) const;  // a sequence of numbers

  // The same, or nullopt when the key is absent (or null).
  std::optional<std::string> optional_string(const std::string& key) const;
  std::optional<double> optional_number(const std::string& key) const;

  // number(key) checked against an interval (see spec_in_range).
  double number_in(const std::string& key, double lo, bool lo_open, double hi, bool hi_open) const;
  double positive(const std::string& key) const;  // in (0, inf)

  // The string value of `key`, which must be one of `choices`.
  std::string choice(const std::string& key, const std::vector<std::string>& choices) const;

 private:
  YAML::Node node_;
  std::string path_;
};

// The "type" of a mapping, read before its other keys are checked.
std::string spec_type(const YAML::Node& node, const std::string& path, const std::vector<std::string>& types);

// Limits on a parsed document: specs are small and hand-written, so deeper nesting or more nodes
// than this is an attack or an accident (YAML aliases can make a few lines expand to billions of
// nodes, or point into their own ancestor: a cycle that recursive readers follow forever).
inline constexpr int kMaxYamlDepth = 64;
inline constexpr long kMaxYamlNodes = 1'000'000;  // counted with aliases expanded

// Parses YAML text (`where` names it in errors: a file, or an option such as "--fresnel"). A syntax
// error is std::invalid_argument("<where>:<line>:<col>: invalid YAML: ..."), an alias cycle, nesting
// deeper than kMaxYamlDepth or more than kMaxYamlNodes nodes is std::invalid_argument("<where>:
// <key path>: ...").
YAML::Node parse_yaml(const std::string& text, const std::string& where);

// parse_yaml of a file's text; a file that cannot be read, or is not a regular file (a FIFO, a
// device, a folder), is std::invalid_argument("<file>: ...").
YAML::Node load_yaml_file(const std::filesystem::path& file);

}  // namespace rsibr
