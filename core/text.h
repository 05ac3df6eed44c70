// Small text helpers shared by readers, writers and error paths: file names and extensions for
// messages and dispatch, library messages folded onto one line (the project's errors are one line
// each), and text from input files made safe to write (valid UTF-8) and to quote in a message.
#pragma once

#include <string>
#include <string_view>

namespace rsibr {

// The extension of `path`, with its dot, lower-cased ("scene.GLB" -> ".glb"; "" when none).
std::string lower_extension(const std::string& path);

// The last component of `path` ("a/b/c.exr" -> "c.exr").
std::string file_name(const std::string& path);

// `s` without trailing blanks and newlines, inner line breaks joined by "; ".
std::string one_line(std::string s);

// True when `s` is well-formed UTF-8 (RFC 3629: no overlong forms, no surrogates, <= U+10FFFF).
bool is_utf8(std::string_view s);

// `s` with every byte that is not part of a well-formed UTF-8 sequence replaced by U+FFFD, so that
// JSON, EXR string attributes and HTML written from input text are valid UTF-8.
std::string valid_utf8(std::string_view s);

// Untrusted text for an error message: control characters and bytes that are not UTF-8 written as
// \xNN, at most `max_chars` characters (then "...(N bytes)"), so one message stays one readable line.
std::string quoted_for_message(std::string_view s, std::size_t max_chars = 48);

}  // namespace rsibr
