// Formatting of numbers in BRDF spec text (bake/brdf_spec.h): the shortest decimal form that
// reads back to the same double, so spec() -> make_brdf() round-trips bit-exactly.
#pragma once

#include "core/vec.h"

#include <charconv>
#include <initializer_list>
#include <string>
#include <string_view>

namespace rsibr::spec_text {

inline std::string number(double x) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, r.ptr);
}

// Concatenation (also sidesteps GCC 12's false -Wrestrict on "literal" + std::string).
inline std::string cat(std::initializer_list<std::string_view> parts) {
  std::string s;
  for (const auto p : parts) s.append(p);
  return s;
}

inline std::string rgb(const Vec3& v) {
  return cat({"[", number(v.x()), ", ", number(v.y()), ", ", number(v.z()), "]"});
}

}  // namespace rsibr::spec_text
