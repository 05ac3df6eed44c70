// A photo set: the folder a photographer brings (or `rsibr synth` writes). photoset.yaml lists the
// camera, the balls in the shot, each view's bracketed exposures and the chessboard images:
//
//   rsibr_photoset: 1                        # format version
//   camera:                                  # all keys optional
//     name: "Canon 5D Mk IV + 50mm"
//     model: camera.cameramodel             # mrcal lens model (intrinsics), relative to the folder
//     colour_space: lin_p3d65               # OCIO space of the linearised camera RGB [the working space]
//   balls:                                   # what calibration looks for, left to right in the frame
//     - {name: chrome, kind: chrome, diameter_m: 0.1}
//     - {name: grey,   kind: grey,   diameter_m: 0.1}
//   views:
//     - name: north                          # unique; names output files (core/safe_name.h)
//       brackets:                            # one entry per exposure of this view
//         - {file: north/0001.png, exposure_s: 0.004, iso: 100, aperture: 8}
//         - {file: north/0002.png}           # exposure left out: read from EXIF (hdr/)
//   chessboards:                             # optional, for intrinsics (calib/)
//     corners: [10, 10]                      # inner corners along x and y
//     spacing_m: 0.03
//     files: [boards/0001.png, boards/0002.png]
//
// Paths are relative to the folder holding photoset.yaml (absolute paths are kept as they are).
// Loading checks the structure strictly (yaml_spec.h: unknown keys, wrong types, non-positive
// exposures are errors; view and ball names must be safe file names, distinct in letter case too:
// core/safe_name.h; the camera's name is free text, bytes that are not UTF-8 replaced by U+FFFD) and that every listed file exists; errors are
// std::invalid_argument("<photoset.yaml>: <key path>: <problem>").
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace rsibr {

// One exposure of a view. Values the YAML leaves out are nullopt (hdr/ fills them from EXIF).
struct BracketPhoto {
  std::filesystem::path file;        // absolute after loading
  std::optional<double> exposure_s;  // shutter time, seconds
  std::optional<double> iso;
  std::optional<double> aperture;  // f-number

  // Exposure relative to ISO 100 at f/1: t * (iso/100) / N^2, with the unknown factors taken as 1.
  // Nullopt when the shutter time is unknown.
  std::optional<double> relative_exposure() const;
};

struct PhotoView {
  std::string name;
  std::vector<BracketPhoto> brackets;  // at least one
};

enum class BallKind { chrome, grey, glossy };
const char* to_string(BallKind k);

struct BallSpec {
  std::string name;
  BallKind kind = BallKind::chrome;
  std::optional<double> diameter_m;
};

struct ChessboardSet {
  int corners_x = 0, corners_y = 0;  // inner corners (>= 2 each)
  double spacing_m = 0;
  std::vector<std::filesystem::path> files;  // absolute after loading
};

struct PhotoSet {
  std::filesystem::path folder;  // holds photoset.yaml (absolute after loading)
  std::string camera_name;
  std::string camera_colour_space;  // OCIO colour space of the linearised camera RGB; empty: the working space
  std::optional<std::filesystem::path> camera_model;  // absolute after loading
  std::vector<BallSpec> balls;
  std::vector<PhotoView> views;
  std::optional<ChessboardSet> chessboards;

  const PhotoView& view(const std::string& name) const;  // throws std::out_of_range
  // Every file the set names (photoset.yaml, the brackets, the chessboards, the camera model):
  // what a verb reading the set must never overwrite.
  std::vector<std::filesystem::path> files() const;
};

// `path` is photoset.yaml or the folder holding it.
PhotoSet load_photo_set(const std::filesystem::path& path);

// Writes `set` as <set.folder>/photoset.yaml (atomically), with paths relative to set.folder when
// they lie under it. load_photo_set(save_photo_set(s)) gives s back.
std::filesystem::path save_photo_set(const PhotoSet& set);

}  // namespace rsibr
