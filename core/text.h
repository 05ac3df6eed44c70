// Small text helpers shared by readers and error paths: file names and extensions for messages and
// dispatch, and library messages folded onto one line (the project's errors are one line each).
#pragma once

#include <string>

namespace rsibr {

// The extension of `path`, with its dot, lower-cased ("scene.GLB" -> ".glb"; "" when none).
std::string lower_extension(const std::string& path);

// The last component of `path` ("a/b/c.exr" -> "c.exr").
std::string file_name(const std::string& path);

// `s` without trailing blanks and newlines, inner line breaks joined by "; ".
std::string one_line(std::string s);

}  // namespace rsibr
