// Inputs are regular files. A FIFO nobody writes, a device or a folder given where a file is
// expected would hang a reader or feed it bytes without end, so every reader checks first.
#pragma once

#include <filesystem>

namespace rsibr {

// Throws FileError(path, "no such file" | "is a folder, expected a file" | "not a regular file (a
// FIFO, a socket or a device)"): one message for a missing input in every verb. Symlinks are followed.
void require_regular_file(const std::filesystem::path& path);

}  // namespace rsibr
