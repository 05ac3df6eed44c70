// Whether a file just written holds what its writer meant to put there, before it is renamed into
// place. Writers do not always see a full disk: a small file fits in a stream's buffer, and the
// flush that fails happens in a destructor that cannot report it (OpenEXR's, std::ofstream's), so
// exit 0 with an empty or truncated output was possible. The checks, all cheap next to the write:
//   - the data reaches the file system (fsync; delayed allocation reports a full disk only here);
//   - the file is not empty (unless empty is what was written);
//   - by extension: an EXR is opened and every part's pixels are read back; a PNG ends with its
//     IEND chunk; a JPEG ends with its end-of-image marker; a JSON file parses.
// Other formats get the first two checks.
#pragma once

#include <filesystem>
#include <string>

namespace rsibr {

// Throws FileError(shown_as, "cannot write: <reason>", output role; what() = "<shown_as>: cannot
// write: <reason>") where `file` fails a check;
// `shown_as` is the name the user gave (the target of a temporary). The format is taken from
// `shown_as`'s extension.
void check_written_file(const std::filesystem::path& file, const std::filesystem::path& shown_as,
                        bool empty_allowed = false);

// Records that `file`, as it is now (size and modification time), passed check_written_file, so a
// second check of it (a temporary written atomically, then committed by formats/output_plan.h) skips
// the read-back.
void note_checked_file(const std::filesystem::path& file);

}  // namespace rsibr
