// Writes that never leave a partial file: the writer fills a temporary name next to the target,
// which is renamed over the target only when the writer returns and the file passes
// formats/written_file_check.h (a full disk that the writer did not notice is caught there); on an
// exception the temporary is removed and the exception propagates. The target's folder must exist.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

namespace rsibr {

void write_atomically(const std::filesystem::path& target,
                      const std::function<void(const std::string& temporary_path)>& writer);

// write_atomically of `text`: the file is closed and checked before the rename, so a write that
// fails late (a full disk shows only when the buffer is flushed) is std::runtime_error("<target>:
// cannot write: <reason>") and leaves nothing.
void write_text_atomically(const std::filesystem::path& target, const std::string& text);

// Throws std::invalid_argument when output names the same file as input (inputs are never
// overwritten).
void check_not_same_file(const std::filesystem::path& input, const std::filesystem::path& output);

// Checking every output of a verb before its work: formats/output_plan.h.

}  // namespace rsibr
