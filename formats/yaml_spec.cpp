#include "formats/yaml_spec.h"

#include "formats/input_file.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace rsibr {

namespace {

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

std::string fmt(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

}  // namespace

void spec_fail(const std::string& path, const std::string& what) { throw std::invalid_argument(path + ": " + what); }

double spec_in_range(double x, const std::string& path, double lo, bool lo_open, double hi, bool hi_open) {
  const bool ok = (lo_open ? x > lo : x >= lo) && (hi_open ? x < hi : x <= hi);
  if (!ok) {
    const std::string range =
        std::string(lo_open ? "(" : "[") + fmt(lo) + "," + (std::isinf(hi) ? "inf" : fmt(hi)) + (hi_open ? ")" : "]");
    spec_fail(path, "must be in " + range + ", got " + fmt(x));
  }
  return x;
}

double spec_number(const YAML::Node& v, const std::string& path) {
  if (!v.IsScalar()) spec_fail(path, "expected a number");
  double x;
  try {
    x = v.as<double>();
  } catch (const YAML::Exception&) {
    spec_fail(path, "expected a number, got '" + v.as<std::string>() + "'");
  }
  if (!std::isfinite(x)) spec_fail(path, "must be finite");
  return x;
}

YamlMap::YamlMap(const YAML::Node& node, std::string path, const std::vector<std::string>& allowed)
    : node_(node), path_(std::move(path)) {
  if (!node_ || !node_.IsMap()) spec_fail(path_, "expected a mapping");
  for (const auto& kv : node_) {
    if (!kv.first.IsScalar()) spec_fail(path_, "keys must be strings");
    const std::string key = kv.first.as<std::string>();
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
      spec_fail(at(key), "unknown key (expected one of: " + join(allowed) + ")");
  }
}

bool YamlMap::has(const std::string& key) const {
  const YAML::Node v = node_[key];
  return v && !v.IsNull();
}

YAML::Node YamlMap::get(const std::string& key) const {
  const YAML::Node v = node_[key];
  if (!v || v.IsNull()) spec_fail(at(key), "missing");
  return v;
}

std::string YamlMap::string(const std::string& key) const {
  const YAML::Node v = get(key);
  if (!v.IsScalar()) spec_fail(at(key), "expected a string");
  return v.as<std::string>();
}

double YamlMap::number(const std::string& key) const { return spec_number(get(key), at(key)); }

long YamlMap::integer(const std::string& key) const {
  const double x = number(key);
  if (x != std::floor(x) || std::abs(x) > 1e15) spec_fail(at(key), "expected a whole number, got " + fmt(x));
  return long(x);
}

bool YamlMap::boolean(const std::string& key) const {
  const YAML::Node v = get(key);
  if (!v.IsScalar()) spec_fail(at(key), "expected true or false");
  try {
    return v.as<bool>();
  } catch (const YAML::Exception&) {
    spec_fail(at(key), "expected true or false, got '" + v.as<std::string>() + "'");
  }
}

Vec3 YamlMap::vec3(const std::string& key) const {
  const YAML::Node v = get(key);
  if (!v.IsSequence() || v.size() != 3) spec_fail(at(key), "expected a sequence of 3 numbers");
  Vec3 c;
  for (std::size_t i = 0; i < 3; ++i) c[int(i)] = spec_number(v[i], at(key) + "[" + std::to_string(i) + "]");
  return c;
}

std::vector<double> YamlMap::numbers(const std::string& key) const {
  const YAML::Node v = get(key);
  if (!v.IsSequence()) spec_fail(at(key), "expected a sequence of numbers");
  std::vector<double> out;
  for (std::size_t i = 0; i < v.size(); ++i) out.push_back(spec_number(v[i], at(key) + "[" + std::to_string(i) + "]"));
  return out;
}

std::optional<std::string> YamlMap::optional_string(const std::string& key) const {
  if (!has(key)) return std::nullopt;
  return string(key);
}

std::optional<double> YamlMap::optional_number(const std::string& key) const {
  if (!has(key)) return std::nullopt;
  return number(key);
}

double YamlMap::number_in(const std::string& key, double lo, bool lo_open, double hi, bool hi_open) const {
  return spec_in_range(number(key), at(key), lo, lo_open, hi, hi_open);
}

double YamlMap::positive(const std::string& key) const {
  return number_in(key, 0, true, std::numeric_limits<double>::infinity(), true);
}

std::string YamlMap::choice(const std::string& key, const std::vector<std::string>& choices) const {
  const std::string s = string(key);
  if (std::find(choices.begin(), choices.end(), s) == choices.end())
    spec_fail(at(key), "unknown value '" + s + "' (expected one of: " + join(choices) + ")");
  return s;
}

std::string spec_type(const YAML::Node& node, const std::string& path, const std::vector<std::string>& types) {
  if (!node || !node.IsMap()) spec_fail(path, "expected a mapping");
  const YAML::Node t = node["type"];
  if (!t || t.IsNull()) spec_fail(path + ".type", "missing");
  if (!t.IsScalar()) spec_fail(path + ".type", "expected a string");
  const std::string type = t.as<std::string>();
  if (std::find(types.begin(), types.end(), type) == types.end())
    spec_fail(path + ".type", "unknown type '" + type + "' (expected one of: " + join(types) + ")");
  return type;
}

namespace {

// Walks the node graph depth first with the chain of ancestors: a node that is one of its own
// ancestors (yaml-cpp registers an anchor before its content, so "&a [*a]" contains itself) is a
// cycle; every visit counts, so aliases that multiply a subtree are bounded by kMaxYamlNodes.
void check_yaml_graph(const YAML::Node& node, std::vector<YAML::Node>& ancestors, long& visits, const std::string& path,
                      const std::string& where) {
  if (++visits > kMaxYamlNodes)
    throw std::invalid_argument(where + ": more than " + std::to_string(kMaxYamlNodes) + " nodes (aliases expanded)");
  for (const YAML::Node& a : ancestors)
    if (a.is(node)) throw std::invalid_argument(where + ": " + path + ": an alias that contains itself (a cycle)");
  if (int(ancestors.size()) >= kMaxYamlDepth)
    throw std::invalid_argument(where + ": " + path + ": nested deeper than " + std::to_string(kMaxYamlDepth) +
                                " levels");
  if (!node.IsMap() && !node.IsSequence()) return;
  ancestors.push_back(node);
  std::size_t i = 0;
  for (const auto& item : node) {
    if (node.IsSequence()) {
      check_yaml_graph(item, ancestors, visits, path + "[" + std::to_string(i++) + "]", where);
    } else {
      const std::string key = item.first.IsScalar() ? item.first.Scalar() : "?";
      check_yaml_graph(item.first, ancestors, visits, path + "." + key, where);
      check_yaml_graph(item.second, ancestors, visits, path + "." + key, where);
    }
  }
  ancestors.pop_back();
}

}  // namespace

YAML::Node parse_yaml(const std::string& text, const std::string& where) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(where + ":" + std::to_string(e.mark.line + 1) + ":" +
                                std::to_string(e.mark.column + 1) + ": invalid YAML: " + e.msg);
  }
  std::vector<YAML::Node> ancestors;
  long visits = 0;
  check_yaml_graph(root, ancestors, visits, "document", where);
  return root;
}

YAML::Node load_yaml_file(const std::filesystem::path& file) {
  require_regular_file(file);
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::invalid_argument(file.string() + ": cannot read");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_yaml(text.str(), file.string());
}

}  // namespace rsibr
