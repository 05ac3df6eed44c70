#include "core/map_set.h"

#include "core/albedo_normalisation.h"
#include "core/atomic_file.h"
#include "core/colour.h"
#include "core/exr_io.h"
#include "core/input_file.h"
#include "core/texel_audit.h"
#include "core/text.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfChromaticitiesAttribute.h>
#include <OpenEXR/ImfFloatVectorAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfMatrixAttribute.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfMultiPartOutputFile.h>
#include <OpenEXR/ImfOutputPart.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfVecAttribute.h>

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

const std::vector<std::string> kReserved = {"view", "worldFromView", "warp", "source", "material", "albedo"};

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
    throw std::runtime_error(path + ": " + e.what());
  }
  const int W = set.width(), H = set.height();
  std::vector<Imf::Header> headers;
  for (std::size_t i = 0; i < set.views.size(); ++i) {
    const MapView& v = set.views[i];
    Imf::Header h(W, H);
    h.setName(part_name(i));
    h.setType(Imf::SCANLINEIMAGE);
    h.compression() = Imf::ZIP_COMPRESSION;
    Imf::addChromaticities(h, Imf::Chromaticities());
    h.insert("rsibr.view", Imf::V3fAttribute(Imath::V3f(float(v.view.x()), float(v.view.y()), float(v.view.z()))));
    Imath::M33f m;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) m[r][c] = float(v.world_from_view(r, c));
    h.insert("rsibr.worldFromView", Imf::M33fAttribute(m));
    h.insert("rsibr.warp", Imf::StringAttribute(to_string(v.warp)));
    h.insert("rsibr.source", Imf::StringAttribute(to_string(v.source)));
    h.insert("rsibr.material", Imf::StringAttribute(valid_utf8(v.material)));
    if (!v.albedo.empty()) h.insert("rsibr.albedo", Imf::FloatVectorAttribute(v.albedo));
    for (const auto& [key, value] : v.attributes) h.insert("rsibr." + key, Imf::StringAttribute(valid_utf8(value)));
    for (const char* c : {"R", "G", "B"}) h.channels().insert(c, Imf::Channel(Imf::FLOAT));
    if (!v.confidence.empty()) h.channels().insert("confidence", Imf::Channel(Imf::FLOAT));
    if (!v.clipped.empty()) h.channels().insert("clipped", Imf::Channel(Imf::FLOAT));
    headers.push_back(h);
  }
  try {
    write_atomically(path, [&](const std::string& tmp) {
      Imf::MultiPartOutputFile file(tmp.c_str(), headers.data(), int(headers.size()));
      for (std::size_t i = 0; i < set.views.size(); ++i) {
        const MapView& v = set.views[i];
        const cv::Mat rgb = v.rgb.isContinuous() ? v.rgb : v.rgb.clone();
        const cv::Mat conf = v.confidence.empty() || v.confidence.isContinuous() ? v.confidence : v.confidence.clone();
        const cv::Mat clip = v.clipped.empty() || v.clipped.isContinuous() ? v.clipped : v.clipped.clone();
        Imf::FrameBuffer fb;
        char* base = reinterpret_cast<char*>(rgb.data);
        const char* names[] = {"R", "G", "B"};
        for (int k = 0; k < 3; ++k)
          fb.insert(names[k], Imf::Slice(Imf::FLOAT, base + k * sizeof(float), 3 * sizeof(float), 3 * sizeof(float) * std::size_t(W)));
        if (!conf.empty())
          fb.insert("confidence", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(conf.data), sizeof(float), sizeof(float) * std::size_t(W)));
        if (!clip.empty())
          fb.insert("clipped", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(clip.data), sizeof(float), sizeof(float) * std::size_t(W)));
        Imf::OutputPart part(file, int(i));
        part.setFrameBuffer(fb);
        part.writePixels(H);
      }
    });
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

bool is_map_set_file(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return false;
  try {
    check_exr_before_reading(path);
    Imf::MultiPartInputFile file(path.c_str());
    return file.parts() >= 1 && file.header(0).hasName() && file.header(0).name() == "view.000";
  } catch (...) {
    return false;
  }
}

MapSet read_map_set(const std::string& path, BadTexels bad, long* zeroed) {
  MapSet set;
  long changed = 0;
  try {
    require_regular_file(path);
    check_exr_before_reading(path);
    Imf::MultiPartInputFile file(path.c_str());
    for (int i = 0; i < file.parts(); ++i) {
      const Imf::Header& h = file.header(i);
      const std::string who = "part " + std::to_string(i) + ": ";
      if (!h.hasName() || h.name() != part_name(std::size_t(i)))
        throw std::runtime_error(who + "expected a part named " + part_name(std::size_t(i)) + " (not a map set?)");
      const auto* view = h.findTypedAttribute<Imf::V3fAttribute>("rsibr.view");
      const auto* T = h.findTypedAttribute<Imf::M33fAttribute>("rsibr.worldFromView");
      const auto* warp = h.findTypedAttribute<Imf::StringAttribute>("rsibr.warp");
      const auto* source = h.findTypedAttribute<Imf::StringAttribute>("rsibr.source");
      if (!view || !T || !warp || !source)
        throw std::runtime_error(who + "missing rsibr.view, rsibr.worldFromView, rsibr.warp or rsibr.source");
      if (!h.channels().findChannel("R") || !h.channels().findChannel("G") || !h.channels().findChannel("B"))
        throw std::runtime_error(who + "missing an R, G or B channel");
      MapView v;
      v.view = Vec3(view->value().x, view->value().y, view->value().z);
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) v.world_from_view(r, c) = T->value()[r][c];
      try {
        v.warp = central_direction_from_string(warp->value());
      } catch (const std::invalid_argument& e) {
        throw std::runtime_error(who + "rsibr.warp: " + e.what());
      }
      try {
        v.source = map_source_from_string(source->value());
      } catch (const std::invalid_argument& e) {
        throw std::runtime_error(who + "rsibr.source: " + e.what());
      }
      if (const auto* m = h.findTypedAttribute<Imf::StringAttribute>("rsibr.material")) v.material = m->value();
      if (const auto* a = h.findTypedAttribute<Imf::FloatVectorAttribute>("rsibr.albedo")) v.albedo = a->value();
      for (auto it = h.begin(); it != h.end(); ++it) {
        const std::string name = it.name();
        if (name.rfind("rsibr.", 0) != 0) continue;
        const std::string key = name.substr(6);
        bool reserved = false;
        for (const std::string& r : kReserved) reserved = reserved || key == r;
        if (reserved) continue;
        if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute())) v.attributes[key] = s->value();
      }
      const Imath::Box2i dw = h.dataWindow();
      const long long W64 = (long long)dw.max.x - dw.min.x + 1, H64 = (long long)dw.max.y - dw.min.y + 1;
      if (W64 < 1 || H64 < 1 || W64 > kMaxMapSize || H64 > kMaxMapSize)
        throw std::runtime_error(who + "a data window of " + std::to_string(W64) + "x" + std::to_string(H64) +
                                 " texels (at most " + std::to_string(kMaxMapSize) + " a side)");
      const int W = int(W64), H = int(H64);
      v.rgb = cv::Mat(H, W, CV_32FC3);
      Imf::FrameBuffer fb;
      char* base = reinterpret_cast<char*>(v.rgb.data);
      const char* names[] = {"R", "G", "B"};
      for (int k = 0; k < 3; ++k)
        fb.insert(names[k], Imf::Slice::Make(Imf::FLOAT, base + k * sizeof(float), dw, 3 * sizeof(float), 3 * sizeof(float) * std::size_t(W)));
      if (h.channels().findChannel("confidence")) {
        v.confidence = cv::Mat(H, W, CV_32FC1);
        fb.insert("confidence", Imf::Slice::Make(Imf::FLOAT, v.confidence.data, dw, sizeof(float), sizeof(float) * std::size_t(W)));
      }
      if (h.channels().findChannel("clipped")) {
        v.clipped = cv::Mat(H, W, CV_32FC1);
        fb.insert("clipped", Imf::Slice::Make(Imf::FLOAT, v.clipped.data, dw, sizeof(float), sizeof(float) * std::size_t(W)));
      }
      Imf::InputPart part(file, i);
      part.setFrameBuffer(fb);
      part.readPixels(dw.min.y, dw.max.y);
      // Pixels in other primaries (a map set written by another tool) go to the working space.
      if (Imf::hasChromaticities(h)) {
        const Imf::Chromaticities c = Imf::chromaticities(h), rec709;
        auto close = [](const Imath::V2f& p, const Imath::V2f& q) { return (p - q).length() < 1e-4f; };
        if (!(close(c.red, rec709.red) && close(c.green, rec709.green) && close(c.blue, rec709.blue) &&
              close(c.white, rec709.white))) {
          const Eigen::Matrix3f m = working_from_chromaticities(c).cast<float>();
          v.rgb.forEach<cv::Vec3f>([&](cv::Vec3f& p, const int*) {
            const Eigen::Vector3f q = m * Eigen::Vector3f(p[0], p[1], p[2]);
            p = cv::Vec3f(q.x(), q.y(), q.z());
          });
        }
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
        if (rgb.bad()) throw std::runtime_error(part_name(std::size_t(i)) + ": " + rgb.describe() + " in R, G, B");
        if (outside)
          throw std::runtime_error(part_name(std::size_t(i)) + ": " + std::to_string(outside) +
                                   " confidence values that are not in [0, 1]");
      } else {
        changed += sanitize_texels(v.rgb) + outside;
      }
      set.views.push_back(std::move(v));
    }
    if (zeroed) *zeroed = changed;
    validate(set);
    set.view_set();  // views that coincide cannot be triangulated: refused here, naming the file
  } catch (const std::exception& e) {
    const std::string what = e.what();
    if (what.rfind(path + ": ", 0) == 0) throw std::runtime_error(what);
    throw std::runtime_error(path + ": " + what);
  }
  return set;
}

}  // namespace rsibr
