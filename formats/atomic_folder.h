// Writing several files into an output folder all or nothing (the --out folders of verbs that
// write many pictures). The files are first written into a staging folder next to the target
// (".<name>.tmp<pid>"); when the target folder does not exist the staging folder is renamed to it,
// otherwise each file is renamed into it (existing files of those names are replaced, others are
// kept). On any error the staging folder is removed and, when this call created the target, the
// target too; the exception propagates.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace rsibr {

// file name (no folders) -> bytes
using FolderContents = std::map<std::string, std::vector<unsigned char>>;

// Throws std::invalid_argument("<folder>: ...") when the folder's parent does not exist, the
// target exists but is not a folder, or a file name has a folder part; std::runtime_error on I/O.
void write_folder_atomically(const std::filesystem::path& folder, const FolderContents& files);

// `folder / file_name` for a file whose name a verb derives from an input (a view's or a ball's
// name), checked to lie directly in `folder`: `file_name` is one path component (no separator, not
// "." or "..", no NUL) and the result's parent, with symlinks resolved, is `folder`'s. Throws
// std::invalid_argument("<folder>: ..."). Every writer renames a finished temporary onto such a
// path, so an existing symlink of that name is replaced, never written through.
std::filesystem::path file_in_folder(const std::filesystem::path& folder, const std::string& file_name);

// The checks of write_folder_atomically alone (run them before long work); also refuses a folder
// that is one of the inputs.
void check_output_folder(const std::filesystem::path& folder, const std::vector<std::filesystem::path>& inputs = {});

}  // namespace rsibr
