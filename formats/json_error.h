// A JSON library error as a user reads it: nlohmann's message without its
// "[json.exception.KIND.N] " prefix, which says nothing to a user.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace rsibr {

inline std::string json_error_text(const nlohmann::json::exception& e) {
  std::string why = e.what();
  if (const std::size_t end = why.find("] "); !why.empty() && why[0] == '[' && end != std::string::npos)
    why = why.substr(end + 2);
  return why;
}

}  // namespace rsibr
