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
  Vec3 vec3(const std::string& key) const;  // a sequence of 3 numbers
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

// Parses a YAML file; a read or syntax error is std::invalid_argument("<file>:<line>:<col>: ...").
YAML::Node load_yaml_file(const std::filesystem::path& file);

}  // namespace rsibr
