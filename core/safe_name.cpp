#include "core/safe_name.h"

#include "core/text.h"

#include <stdexcept>

namespace rsibr {
namespace {

bool alnum(unsigned char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9'); }

std::string describe_byte(unsigned char c) {
  if (c == '/' || c == '\\') return std::string("a path separator '") + char(c) + "'";
  if (c < 0x20 || c == 0x7F) return "a control character";
  if (c >= 0x80) return "a character that is not ASCII";
  return std::string("'") + char(c) + "'";
}

}  // namespace

std::string name_problem(std::string_view name) {
  if (name.empty()) return "empty name";
  if (name.size() > kMaxNameLength)
    return "a name of " + std::to_string(name.size()) + " characters (at most " + std::to_string(kMaxNameLength) + ")";
  if (name == "." || name == "..") return "a name that is a folder reference";
  const unsigned char first = static_cast<unsigned char>(name[0]);
  if (!alnum(first))
    return "a name starting with " + describe_byte(first) + " (the first character must be a letter or a digit)";
  for (const char ch : name) {
    const unsigned char c = static_cast<unsigned char>(ch);
    if (!alnum(c) && c != '_' && c != '-' && c != '.')
      return "a name containing " + describe_byte(c) + " (use letters, digits, '_', '-' and '.')";
  }
  return "";
}

void require_safe_name(std::string_view name, const std::string& where) {
  const std::string problem = name_problem(name);
  if (!problem.empty()) throw std::invalid_argument(where + ": " + problem + ": '" + quoted_for_message(name) + "'");
}

void DistinctNames::add(const std::string& name, const std::string& where, const std::string& kind) {
  require_safe_name(name, where);
  std::string folded = name;
  for (char& c : folded)
    if (c >= 'A' && c <= 'Z') c = char(c - 'A' + 'a');
  const auto [it, inserted] = folded_.emplace(folded, name);
  if (inserted) return;
  if (it->second == name) throw std::invalid_argument(where + ": duplicate " + kind + " name '" + name + "'");
  throw std::invalid_argument(where + ": " + kind + " name '" + name + "' clashes with '" + it->second +
                              "' (names must differ in more than letter case)");
}

}  // namespace rsibr
