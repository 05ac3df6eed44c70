#include "formats/map_set.h"

#include "core/albedo_normalisation.h"
#include "formats/atomic_file.h"
#include "core/colour.h"
#include "formats/exr_file.h"
#include "formats/exr_io.h"
#include "formats/input_file.h"
#include "core/texel_audit.h"
#include "core/text.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace rsibr {

const char* to_string(MapSource source) { return source == MapSource::Captured ? "captured" : "computed"; }

MapSource map_source_from_string(const std::string& name) {
  if (name == "computed") return MapSource::Computed;
  if (name == "captured") return MapSource::Captured;
  throw std::invalid_argument("'" + name + "' is neither computed nor captured");
}

namespace {

// A sphere map wider than this is a corrupt or hostile header, not a map (rsibr bake --res stops
// there too; 8192^2 RGB float is 0.8 GB).
constexpr long long kMaxMapSize = 8192;

std::string part_name(std::size_t i) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "view.%03zu", i);
  return buf;
}

const std::vector<std::string> kReserved = {"view", "worldFromView", "warp", "source", "material", "albedo", "image"};

}  // namespace

ViewSet MapSet::view_set() const {
  std::vector<Vec3> dirs;
  for (const MapView& v : views) dirs.push_back(v.view);
  return ViewSet(dirs);
}

void validate(const MapSet& set) {
  if (set.views.empty()) throw std::invalid_argument("map set has no views");
  for (std::size_t i = 0; i < set.views.size(); ++i) {
    const MapView& v = set.views[i];
    const std::string who = part_name(i) + ": ";
    if (v.rgb.empty() || v.rgb.type() != CV_32FC3) throw std::invalid_argument(who + "pixels must be float RGB");
    if (v.rgb.size() != set.views.front().rgb.size()) throw std::invalid_argument(who + "size differs from view.000");
    if (!v.confidence.empty() && (v.confidence.type() != CV_32FC1 || v.confidence.size() != v.rgb.size()))
      throw std::invalid_argument(who + "confidence must be one float channel of the map's size");
    if (!v.clipped.empty() && (v.clipped.type() != CV_32FC1 || v.clipped.size() != v.rgb.size()))
      throw std::invalid_argument(who + "clipped must be one float channel of the map's size");
    if (!v.view.allFinite() || std::abs(v.view.norm() - 1.0) > 1e-5)
      throw std::invalid_argument(who + "view direction is not a unit vector");
    const Mat3& T = v.world_from_view;
    if (!T.allFinite() || (T.transpose() * T - Mat3::Identity()).cwiseAbs().maxCoeff() > 1e-5 || T.determinant() < 0)
      throw std::invalid_argument(who + "worldFromView is not a rotation");
    if ((T.col(2) - v.view).norm() > 1e-5)
      throw std::invalid_argument(who + "worldFromView's third column is not the view direction");
    if (v.albedo != set.views.front().albedo)
      throw std::invalid_argument(who + "albedo table differs from view.000's (a set shares one BRDF)");
    if (!v.albedo.empty()) {
      try {
        check_albedo_table(v.albedo);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(who + e.what());
      }
    }
    for (const auto& [key, value] : v.attributes) {
      for (const std::string& r : kReserved)
        if (key == r) throw std::invalid_argument(who + "attribute '" + key + "' is reserved");
      if (("rsibr." + key).size() > kMaxAttributeName)
        throw std::invalid_argument(who + "attribute name 'rsibr." + key + "' is longer than 31 characters");
    }
  }
}

void write_map_set(const std::string& path, const MapSet& set) {
  try {
    validate(set);
  } catch (const std::exception& e) {
    throw FileError(path, e.what(), {}, FileRole::Output);
  }
  std::vector<ExrPartOut> parts;
  for (std::size_t i = 0; i < set.views.size(); ++i) {
    const MapView& v = set.views[i];
    ExrPartOut part;
    part.name = part_name(i);
    for (int k = 0; k < 3; ++k) part.channels.push_back({std::string(1, "RGB"[k]), v.rgb, k});
    if (!v.confidence.empty()) part.channels.push_back({"confidence", v.confidence, 0});
    if (!v.clipped.empty()) part.channels.push_back({"clipped", v.clipped, 0});
    part.attributes = {{"rsibr.view", v.view},
                       {"rsibr.worldFromView", v.world_from_view},
                       {"rsibr.warp", std::string(to_string(v.warp))},
                       {"rsibr.source", std::string(to_string(v.source))},
                       {"rsibr.material", v.material}};
    if (!v.albedo.empty()) part.attributes.emplace_back("rsibr.albedo", v.albedo);
    if (!v.image.empty()) part.attributes.emplace_back("rsibr.image", v.image);
    for (const auto& [key, value] : v.attributes) part.attributes.emplace_back("rsibr." + key, value);
    parts.push_back(std::move(part));
  }
  write_exr(path, parts);
}

bool is_map_set_file(const std::string& path) {
  // Not a probe by exception: the file's kind is read from its first bytes and part names.
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec) || !looks_like_exr(path)) return false;
  try {
    const ExrFileIn file(path);
    return file.parts().front().name == "view.000";
  } catch (const FileError&) {
    return false;  // an EXR file whose header does not read is not a map set either
  }
}

MapSet read_map_set(const std::string& path, BadTexels bad, long* zeroed) {
  MapSet set;
  long changed = 0;
  const ExrFileIn file(path);
  for (int i = 0; i < int(file.parts().size()); ++i) {
    const ExrPartIn& h = file.parts()[std::size_t(i)];
    const std::string who = "part " + std::to_string(i);
    auto fail = [&](const std::string& problem) { throw FileError(path, problem, who); };
    if (h.name != part_name(std::size_t(i)))
      fail("expected a part named " + part_name(std::size_t(i)) + " (not a map set?)");
    const auto view = h.get<Vec3>("rsibr.view");
    const auto T = h.get<Mat3>("rsibr.worldFromView");
    const auto warp = h.get<std::string>("rsibr.warp");
    const auto source = h.get<std::string>("rsibr.source");
    if (!view || !T || !warp || !source) fail("missing rsibr.view, rsibr.worldFromView, rsibr.warp or rsibr.source");
    if (!h.has_channel("R") || !h.has_channel("G") || !h.has_channel("B")) fail("missing an R, G or B channel");
    if (h.width > kMaxMapSize || h.height > kMaxMapSize)
      fail("a data window of " + std::to_string(h.width) + "x" + std::to_string(h.height) + " texels (at most " +
           std::to_string(kMaxMapSize) + " a side)");
    MapView v;
    v.view = *view;
    v.world_from_view = *T;
    try {
      v.warp = central_direction_from_string(*warp);
    } catch (const std::invalid_argument& e) {
      fail(std::string("rsibr.warp: ") + e.what());
    }
    try {
      v.source = map_source_from_string(*source);
    } catch (const std::invalid_argument& e) {
      fail(std::string("rsibr.source: ") + e.what());
    }
    if (const auto m = h.get<std::string>("rsibr.material")) v.material = *m;
    if (const auto a = h.get<std::vector<float>>("rsibr.albedo")) v.albedo = *a;
    if (const auto m = h.get<std::string>("rsibr.image")) v.image = *m;
    for (const auto& [key, value] : h.strings_with_prefix("rsibr.")) {
      bool reserved = false;
      for (const std::string& r : kReserved) reserved = reserved || key == r;
      if (!reserved) v.attributes[key] = value;
    }
    v.rgb = file.read(i, {"R", "G", "B"});
    if (h.has_channel("confidence")) v.confidence = file.read(i, {"confidence"});
    if (h.has_channel("clipped")) v.clipped = file.read(i, {"clipped"});
    // Pixels in other primaries (a map set written by another tool) go to the working space.
    if (h.working_from_file) {
      const Eigen::Matrix3f m = h.working_from_file->cast<float>();
      v.rgb.forEach<cv::Vec3f>([&](cv::Vec3f& p, const int*) {
        const Eigen::Vector3f q = m * Eigen::Vector3f(p[0], p[1], p[2]);
        p = cv::Vec3f(q.x(), q.y(), q.z());
      });
    }
    // Values no computation can use: refused, or zeroed on request.
    const TexelAudit rgb = audit_texels(v.rgb);
    long outside = 0;  // confidences that are not finite or not in [0, 1]
    for (int r = 0; r < v.confidence.rows; ++r) {
      float* w = v.confidence.ptr<float>(r);
      for (int x = 0; x < v.confidence.cols; ++x) {
        if (std::isfinite(w[x]) && w[x] >= 0 && w[x] <= 1) continue;
        ++outside;
        if (bad == BadTexels::zero) w[x] = std::isnan(w[x]) ? 0.f : std::clamp(w[x], 0.f, 1.f);
      }
    }
    if (bad == BadTexels::refuse) {
      if (rgb.bad()) throw FileError(path, rgb.describe() + " in R, G, B", part_name(std::size_t(i)));
      if (outside)
        throw FileError(path, std::to_string(outside) + " confidence values that are not in [0, 1]",
                        part_name(std::size_t(i)));
    } else {
      changed += sanitize_texels(v.rgb) + outside;
    }
    set.views.push_back(std::move(v));
  }
  if (zeroed) *zeroed = changed;
  with_file(path, [&] {
    validate(set);
    set.view_set();  // views that coincide cannot be triangulated: refused here, naming the file
  });
  return set;
}

}  // namespace rsibr
