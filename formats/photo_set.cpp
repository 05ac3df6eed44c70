#include "formats/photo_set.h"

#include "formats/atomic_file.h"
#include "core/safe_name.h"
#include "core/text.h"
#include "formats/yaml_spec.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace rsibr {

namespace fs = std::filesystem;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

fs::path resolve(const fs::path& folder, const std::string& p, const std::string& key) {
  if (p.empty()) spec_fail(key, "empty path");
  const fs::path full = fs::path(p).is_absolute() ? fs::path(p) : folder / p;
  std::error_code ec;
  if (!fs::exists(full, ec)) spec_fail(key, "no such file '" + full.string() + "'");
  if (!fs::is_regular_file(full, ec)) spec_fail(key, "'" + full.string() + "' is not a regular file");
  return fs::absolute(full).lexically_normal();
}

std::string relative_to(const fs::path& folder, const fs::path& file) {
  const fs::path rel = file.lexically_relative(folder);
  if (!rel.empty() && *rel.begin() != "..") return rel.generic_string();
  return file.generic_string();
}

BallKind ball_kind(const std::string& s) {
  if (s == "chrome") return BallKind::chrome;
  if (s == "grey") return BallKind::grey;
  return BallKind::glossy;
}

PhotoSet parse(const YAML::Node& root, const fs::path& folder) {
  PhotoSet set;
  set.folder = folder;
  YamlMap top(root, "photoset", {"rsibr_photoset", "camera", "balls", "views", "chessboards"});
  if (top.integer("rsibr_photoset") != 1) spec_fail(top.at("rsibr_photoset"), "unsupported version (expected 1)");
  if (top.has("camera")) {
    YamlMap cam(top.get("camera"), top.at("camera"), {"name", "model", "colour_space"});
    set.camera_name = valid_utf8(cam.optional_string("name").value_or(""));
    set.camera_colour_space = valid_utf8(cam.optional_string("colour_space").value_or(""));
    if (cam.has("model")) set.camera_model = resolve(folder, cam.string("model"), cam.at("model"));
  }
  if (top.has("balls")) {
    const YAML::Node balls = top.get("balls");
    if (!balls.IsSequence()) spec_fail(top.at("balls"), "expected a sequence");
    DistinctNames names;
    for (std::size_t i = 0; i < balls.size(); ++i) {
      YamlMap b(balls[i], top.at("balls") + "[" + std::to_string(i) + "]", {"name", "kind", "diameter_m"});
      BallSpec spec;
      spec.name = b.string("name");
      names.add(spec.name, b.at("name"), "ball");
      spec.kind = ball_kind(b.choice("kind", {"chrome", "grey", "glossy"}));
      if (b.has("diameter_m")) spec.diameter_m = b.positive("diameter_m");
      set.balls.push_back(spec);
    }
  }
  const YAML::Node views = top.get("views");
  if (!views.IsSequence() || views.size() == 0) spec_fail(top.at("views"), "expected a non-empty sequence");
  DistinctNames names;
  for (std::size_t i = 0; i < views.size(); ++i) {
    YamlMap v(views[i], top.at("views") + "[" + std::to_string(i) + "]", {"name", "brackets"});
    PhotoView view;
    view.name = v.string("name");
    names.add(view.name, v.at("name"), "view");
    const YAML::Node brackets = v.get("brackets");
    if (!brackets.IsSequence() || brackets.size() == 0) spec_fail(v.at("brackets"), "expected a non-empty sequence");
    for (std::size_t j = 0; j < brackets.size(); ++j) {
      YamlMap b(brackets[j], v.at("brackets") + "[" + std::to_string(j) + "]",
                {"file", "exposure_s", "iso", "aperture"});
      BracketPhoto photo;
      photo.file = resolve(folder, b.string("file"), b.at("file"));
      if (b.has("exposure_s")) photo.exposure_s = b.positive("exposure_s");
      if (b.has("iso")) photo.iso = b.positive("iso");
      if (b.has("aperture")) photo.aperture = b.positive("aperture");
      view.brackets.push_back(photo);
    }
    set.views.push_back(std::move(view));
  }
  if (top.has("chessboards")) {
    YamlMap c(top.get("chessboards"), top.at("chessboards"), {"corners", "spacing_m", "files"});
    ChessboardSet boards;
    const std::vector<double> corners = c.numbers("corners");
    if (corners.size() != 2) spec_fail(c.at("corners"), "expected [x, y]");
    for (int k = 0; k < 2; ++k) {
      const double n = corners[std::size_t(k)];
      if (n != std::floor(n) || n < 2 || n > 1000) spec_fail(c.at("corners"), "expected whole numbers >= 2");
    }
    boards.corners_x = int(corners[0]);
    boards.corners_y = int(corners[1]);
    boards.spacing_m = c.positive("spacing_m");
    const YAML::Node files = c.get("files");
    if (!files.IsSequence() || files.size() == 0) spec_fail(c.at("files"), "expected a non-empty sequence");
    for (std::size_t j = 0; j < files.size(); ++j) {
      const std::string key = c.at("files") + "[" + std::to_string(j) + "]";
      if (!files[j].IsScalar()) spec_fail(key, "expected a path");
      boards.files.push_back(resolve(folder, files[j].as<std::string>(), key));
    }
    set.chessboards = std::move(boards);
  }
  return set;
}

// Shortest text that reads back to the same double.
std::string number(double x) {
  std::ostringstream s;
  s.precision(17);
  s << x;
  for (int p = 1; p <= 17; ++p) {
    std::ostringstream t;
    t.precision(p);
    t << x;
    if (std::stod(t.str()) == x) return t.str();
  }
  return s.str();
}

}  // namespace

std::optional<double> BracketPhoto::relative_exposure() const {
  if (!exposure_s) return std::nullopt;
  const double n = aperture.value_or(1.0);
  return *exposure_s * (iso.value_or(100.0) / 100.0) / (n * n);
}

const char* to_string(BallKind k) {
  switch (k) {
    case BallKind::chrome: return "chrome";
    case BallKind::grey: return "grey";
    case BallKind::glossy: return "glossy";
  }
  return "?";
}

const PhotoView& PhotoSet::view(const std::string& name) const {
  for (const PhotoView& v : views)
    if (v.name == name) return v;
  throw std::out_of_range("photo set has no view '" + quoted_for_message(name) + "'");
}

std::vector<fs::path> PhotoSet::files() const {
  std::vector<fs::path> out = {folder / "photoset.yaml"};
  if (camera_model) out.push_back(*camera_model);
  for (const PhotoView& v : views)
    for (const BracketPhoto& b : v.brackets) out.push_back(b.file);
  if (chessboards) out.insert(out.end(), chessboards->files.begin(), chessboards->files.end());
  return out;
}

PhotoSet load_photo_set(const fs::path& path) {
  std::error_code ec;
  const fs::path yaml = fs::is_directory(path, ec) ? path / "photoset.yaml" : path;
  const YAML::Node root = load_yaml_file(yaml);
  try {
    return parse(root, fs::absolute(yaml).parent_path().lexically_normal());
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(yaml.string() + ": " + e.what());
  }
}

fs::path save_photo_set(const PhotoSet& set) {
  const fs::path folder = fs::absolute(set.folder).lexically_normal();
  YAML::Emitter out;
  out << YAML::BeginMap << YAML::Key << "rsibr_photoset" << YAML::Value << 1;
  if (!set.camera_name.empty() || set.camera_model || !set.camera_colour_space.empty()) {
    out << YAML::Key << "camera" << YAML::Value << YAML::BeginMap;
    if (!set.camera_name.empty()) out << YAML::Key << "name" << YAML::Value << YAML::DoubleQuoted << set.camera_name;
    if (set.camera_model) out << YAML::Key << "model" << YAML::Value << relative_to(folder, *set.camera_model);
    if (!set.camera_colour_space.empty())
      out << YAML::Key << "colour_space" << YAML::Value << YAML::DoubleQuoted << set.camera_colour_space;
    out << YAML::EndMap;
  }
  if (!set.balls.empty()) {
    out << YAML::Key << "balls" << YAML::Value << YAML::BeginSeq;
    for (const BallSpec& b : set.balls) {
      out << YAML::Flow << YAML::BeginMap << YAML::Key << "name" << YAML::Value << b.name << YAML::Key << "kind"
          << YAML::Value << to_string(b.kind);
      if (b.diameter_m) out << YAML::Key << "diameter_m" << YAML::Value << number(*b.diameter_m);
      out << YAML::EndMap;
    }
    out << YAML::EndSeq;
  }
  out << YAML::Key << "views" << YAML::Value << YAML::BeginSeq;
  for (const PhotoView& v : set.views) {
    out << YAML::BeginMap << YAML::Key << "name" << YAML::Value << v.name << YAML::Key << "brackets" << YAML::Value
        << YAML::BeginSeq;
    for (const BracketPhoto& b : v.brackets) {
      out << YAML::Flow << YAML::BeginMap << YAML::Key << "file" << YAML::Value << relative_to(folder, b.file);
      if (b.exposure_s) out << YAML::Key << "exposure_s" << YAML::Value << number(*b.exposure_s);
      if (b.iso) out << YAML::Key << "iso" << YAML::Value << number(*b.iso);
      if (b.aperture) out << YAML::Key << "aperture" << YAML::Value << number(*b.aperture);
      out << YAML::EndMap;
    }
    out << YAML::EndSeq << YAML::EndMap;
  }
  out << YAML::EndSeq;
  if (set.chessboards) {
    const ChessboardSet& c = *set.chessboards;
    out << YAML::Key << "chessboards" << YAML::Value << YAML::BeginMap << YAML::Key << "corners" << YAML::Value
        << YAML::Flow << YAML::BeginSeq << c.corners_x << c.corners_y << YAML::EndSeq << YAML::Key << "spacing_m"
        << YAML::Value << number(c.spacing_m) << YAML::Key << "files" << YAML::Value << YAML::BeginSeq;
    for (const fs::path& f : c.files) out << relative_to(folder, f);
    out << YAML::EndSeq << YAML::EndMap;
  }
  out << YAML::EndMap;
  const fs::path target = folder / "photoset.yaml";
  write_text_atomically(
      target, std::string("# rsibr photo set (formats/photo_set.h describes the format)\n") + out.c_str() + "\n");
  return target;
}

}  // namespace rsibr
