// Names read from input files (photo-set views and balls, pose-file views, scene balls, the view
// name an image carries in its header) become parts of output file names: hdr/<view>.exr,
// maps/captured-<ball>.exr, truth/views/<view>_radiance.exr. A name from a file someone handed the
// user must never turn into a path outside the output folder, a hidden file, or two files that
// collide on a case-insensitive file system, so every such name is checked where it is read:
//
//   1 to 64 characters from [A-Za-z0-9_.-], the first a letter or a digit
//
// which rules out "", ".", "..", "/", "\", absolute paths, hidden files, option look-alikes
// ("-v"), control characters and bytes that are not ASCII. Anything else is refused with one line
// naming the file, the key and the name; nothing is renamed behind the user's back.
#pragma once

#include <map>
#include <string>
#include <string_view>

namespace rsibr {

inline constexpr std::size_t kMaxNameLength = 64;

// What is wrong with `name` in words ("contains '/'"), or "" when it is a safe name.
std::string name_problem(std::string_view name);

// Throws std::invalid_argument("<where>: <problem> in name '<name as quoted_for_message>'") unless
// `name` is safe. `where` names the file and key ("photoset.yaml: photoset.views[2].name").
void require_safe_name(std::string_view name, const std::string& where);

// Names of one kind (the views of a photo set, its balls) that must stay distinct as file names:
// equal after ASCII case folding is a clash (north.exr and North.exr are one file on macOS and
// Windows file systems).
class DistinctNames {
 public:
  // Checks `name` with require_safe_name, then against the names added before; throws
  // std::invalid_argument("<where>: duplicate <kind> name '<name>'" or "... clashes with '<other>'
  // (names must differ in more than letter case)").
  void add(const std::string& name, const std::string& where, const std::string& kind);

 private:
  std::map<std::string, std::string> folded_;  // lower-cased -> as first given
};

}  // namespace rsibr
