#include "calib/balls/balls_file.h"

#include "formats/json_error.h"
#include "core/vec.h"
#include "formats/atomic_file.h"

#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace rsibr {

namespace {

constexpr int kVersion = 1;

// JSON has no infinity: a measure that is not finite (a Lambert fit that failed) is written null.
nlohmann::json number(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }
double number(const nlohmann::json& j) {
  return j.is_null() ? std::numeric_limits<double>::infinity() : j.get<double>();
}

// An int field: a JSON integer in int's range (a float would be cast, out of range undefined).
int integer(const nlohmann::json& j) {
  if (!j.is_number_integer()) throw std::invalid_argument("expected an integer, got " + j.dump());
  if (j.is_number_unsigned() ? j.get<std::uint64_t>() > std::uint64_t(std::numeric_limits<int>::max())
                             : (j.get<std::int64_t>() < std::numeric_limits<int>::min() ||
                                j.get<std::int64_t>() > std::numeric_limits<int>::max()))
    throw std::invalid_argument("integer out of range: " + j.dump());
  return int(j.get<std::int64_t>());
}

nlohmann::json candidate_json(const BallCandidate& c) {
  const BallLocation& l = c.loc;
  nlohmann::json outline = nlohmann::json::array();
  for (const Vec2& p : l.outline_px) outline.push_back(p.x()), outline.push_back(p.y());
  return {{"centre_px", {l.centre_px.x(), l.centre_px.y()}},
          {"radius_px", l.radius_px},
          {"cone",
           {{"axis", {l.fit.cone.axis.x(), l.fit.cone.axis.y(), l.fit.cone.axis.z()}},
            {"half_angle", l.fit.cone.half_angle}}},
          {"rms_px", l.fit.rms_px},
          {"inliers", l.fit.inliers},
          {"lines_inside", l.lines_inside},
          {"outline_px", outline},
          {"residual_px", l.fit.residual_px},
          {"inlier_fraction", c.inlier_fraction},
          {"outline_support", c.outline_support},
          {"texture", c.texture},
          {"rim_texture", c.rim_texture},
          {"mirror_score", c.mirror_score},
          {"rim_radial", c.rim_radial},
          {"diffuse_residual", number(c.diffuse_residual)},
          {"shading_texture", number(c.shading_texture)},
          {"frame_fraction", c.frame_fraction},
          {"cut", c.cut}};
}

BallCandidate candidate_from_json(const nlohmann::json& j) {
  BallCandidate c;
  BallLocation& l = c.loc;
  l.centre_px = Vec2(j.at("centre_px").at(0).get<double>(), j.at("centre_px").at(1).get<double>());
  l.radius_px = j.at("radius_px").get<double>();
  const nlohmann::json& a = j.at("cone").at("axis");
  l.fit.cone.axis = Vec3(a.at(0).get<double>(), a.at(1).get<double>(), a.at(2).get<double>());
  l.fit.cone.half_angle = j.at("cone").at("half_angle").get<double>();
  l.fit.rms_px = j.at("rms_px").get<double>();
  l.fit.inliers = integer(j.at("inliers"));
  l.lines_inside = integer(j.at("lines_inside"));
  const nlohmann::json& o = j.at("outline_px");
  if (!o.is_array() || o.size() % 2) throw std::invalid_argument("outline_px: expected x, y pairs");
  for (std::size_t i = 0; i < o.size(); i += 2) l.outline_px.emplace_back(o[i].get<double>(), o[i + 1].get<double>());
  l.fit.residual_px = j.at("residual_px").get<std::vector<double>>();
  if (l.fit.residual_px.size() != l.outline_px.size())
    throw std::invalid_argument("residual_px: one per outline point expected");
  c.inlier_fraction = j.at("inlier_fraction").get<double>();
  c.outline_support = j.at("outline_support").get<double>();
  c.texture = j.at("texture").get<double>();
  c.rim_texture = j.at("rim_texture").get<double>();
  c.mirror_score = j.at("mirror_score").get<double>();
  c.rim_radial = j.at("rim_radial").get<double>();
  c.diffuse_residual = number(j.at("diffuse_residual"));
  c.shading_texture = number(j.at("shading_texture"));
  c.frame_fraction = j.at("frame_fraction").get<double>();
  c.cut = j.at("cut").get<bool>();
  if (!l.centre_px.allFinite() || !(l.radius_px > 0) || !l.fit.cone.axis.allFinite() ||
      !(l.fit.cone.half_angle > 0 && l.fit.cone.half_angle < kPi / 2))
    throw std::invalid_argument("a candidate's circle or cone is not a ball's");
  return c;
}

// The centre of a ball minus the chrome ball's, camera frame, chrome radii (balls_file.h).
nlohmann::json offset_from_chrome(const FoundView& v, const std::vector<ListedBall>& listed, std::size_t b) {
  int chrome = -1;
  for (std::size_t i = 0; i < listed.size(); ++i)
    if (listed[i].kind == BallKind::chrome && chrome < 0) chrome = int(i);
  if (chrome < 0 || int(b) == chrome) return nullptr;
  const int kc = v.balls[std::size_t(chrome)].candidate, kb = v.balls[b].candidate;
  if (kc < 0 || kb < 0 || !listed[b].diameter_m || !listed[std::size_t(chrome)].diameter_m) return nullptr;
  const double scale = *listed[b].diameter_m / *listed[std::size_t(chrome)].diameter_m;
  const BallCone& c = v.candidates[std::size_t(kc)].loc.fit.cone;
  const BallCone& g = v.candidates[std::size_t(kb)].loc.fit.cone;
  const Vec3 d = scale * g.centre(1.0) - c.centre(1.0);
  return {d.x(), d.y(), d.z()};
}

nlohmann::json view_json(const FoundView& v, const std::vector<ListedBall>& listed, bool with_candidates) {
  nlohmann::json balls = nlohmann::json::array();
  for (std::size_t b = 0; b < listed.size(); ++b) {
    const FoundBall& f = v.balls[b];
    nlohmann::json bj = {{"ball", listed[b].name},
                         {"kind", to_string(listed[b].kind)},
                         {"status", f.status},
                         {"candidate", f.candidate},
                         {"note", f.note}};
    if (f.candidate >= 0) {
      const BallCandidate& c = v.candidates[std::size_t(f.candidate)];
      bj.update({{"centre_px", {c.loc.centre_px.x(), c.loc.centre_px.y()}},
                 {"radius_px", c.loc.radius_px},
                 {"confidence", std::min(1.0, c.outline_support)},
                 {"offset_from_chrome", offset_from_chrome(v, listed, b)}});
    }
    balls.push_back(bj);
  }
  nlohmann::json j = {
      {"name", v.name},
      {"size", {v.width, v.height}},
      {"lens",
       {{"model", v.lens.name()}, {"intrinsics", v.lens.intrinsics()}, {"size", {v.lens.width(), v.lens.height()}}}},
      {"balls", balls}};
  if (with_candidates) {
    j["candidates"] = nlohmann::json::array();
    for (const BallCandidate& c : v.candidates) j["candidates"].push_back(candidate_json(c));
  }
  return j;
}

nlohmann::json listed_json(const std::vector<ListedBall>& listed) {
  nlohmann::json out = nlohmann::json::array();
  for (const ListedBall& b : listed)
    out.push_back({{"name", b.name},
                   {"kind", to_string(b.kind)},
                   {"diameter_m", b.diameter_m ? nlohmann::json(*b.diameter_m) : nullptr}});
  return out;
}

BallKind kind_from(const std::string& s) {
  for (BallKind k : {BallKind::chrome, BallKind::grey, BallKind::glossy})
    if (s == to_string(k)) return k;
  throw std::invalid_argument("kind '" + s + "': expected chrome, grey or glossy");
}

}  // namespace

void check_listed_balls(const ShootBalls& balls, const std::vector<ListedBall>& listed, const std::string& what) {
  const std::vector<ListedBall> want =
      listed.empty() ? std::vector<ListedBall>{{"chrome", BallKind::chrome, {}}} : listed;
  bool same = want.size() == balls.listed.size();
  for (std::size_t b = 0; same && b < want.size(); ++b)
    same = want[b].name == balls.listed[b].name && want[b].kind == balls.listed[b].kind &&
           want[b].diameter_m == balls.listed[b].diameter_m;
  if (same) return;
  auto names = [](const std::vector<ListedBall>& l) {
    std::string s;
    for (const ListedBall& b : l) s += (s.empty() ? "" : ", ") + b.name + " (" + to_string(b.kind) + ")";
    return s;
  };
  throw std::invalid_argument(what + ": its balls (" + names(balls.listed) + ") are not the photo set's (" +
                              names(want) + ")");
}

nlohmann::json balls_summary_json(const ShootBalls& balls) {
  nlohmann::json views = nlohmann::json::array();
  for (const FoundView& v : balls.views) views.push_back(view_json(v, balls.listed, false));
  return {{"balls", listed_json(balls.listed)}, {"views", views}};
}

void write_balls_file(const std::filesystem::path& file, const ShootBalls& balls) {
  nlohmann::json j = {{"format", "rsibr-balls"}, {"version", kVersion}, {"balls", listed_json(balls.listed)}};
  j["views"] = nlohmann::json::array();
  for (const FoundView& v : balls.views) j["views"].push_back(view_json(v, balls.listed, true));
  write_text_atomically(file, j.dump() + "\n");
}

ShootBalls read_balls_file(const std::filesystem::path& file) {
  const std::string what = file.string();
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::invalid_argument(what + ": cannot be read");
  std::stringstream text;
  text << in.rdbuf();
  try {
    const nlohmann::json j = nlohmann::json::parse(text.str());
    if (j.at("format").get<std::string>() != "rsibr-balls") throw std::invalid_argument("not an rsibr balls file");
    if (integer(j.at("version")) != kVersion)
      throw std::invalid_argument("version " + std::to_string(integer(j.at("version"))) + ", this rsibr reads " +
                                  std::to_string(kVersion));
    ShootBalls out;
    for (const nlohmann::json& b : j.at("balls")) {
      ListedBall l{b.at("name").get<std::string>(), kind_from(b.at("kind").get<std::string>()), std::nullopt};
      if (!b.at("diameter_m").is_null()) l.diameter_m = b.at("diameter_m").get<double>();
      out.listed.push_back(l);
    }
    for (const nlohmann::json& vj : j.at("views")) {
      FoundView v;
      v.name = vj.at("name").get<std::string>();
      v.width = integer(vj.at("size").at(0));
      v.height = integer(vj.at("size").at(1));
      if (v.width <= 0 || v.height <= 0) throw std::invalid_argument("view " + v.name + ": size must be positive");
      const nlohmann::json& lj = vj.at("lens");
      v.lens = LensModel(lj.at("model").get<std::string>(), lj.at("intrinsics").get<std::vector<double>>(),
                         integer(lj.at("size").at(0)), integer(lj.at("size").at(1)));
      for (const nlohmann::json& c : vj.at("candidates")) v.candidates.push_back(candidate_from_json(c));
      const nlohmann::json& bs = vj.at("balls");
      if (bs.size() != out.listed.size())
        throw std::invalid_argument("view " + v.name + ": " + std::to_string(bs.size()) + " balls, " +
                                    std::to_string(out.listed.size()) + " listed");
      for (std::size_t b = 0; b < bs.size(); ++b) {
        FoundBall f{bs[b].at("status").get<std::string>(), integer(bs[b].at("candidate")),
                    bs[b].at("note").get<std::string>()};
        if (bs[b].at("ball").get<std::string>() != out.listed[b].name)
          throw std::invalid_argument("view " + v.name + ": ball " + std::to_string(b) + " is not " +
                                      out.listed[b].name);
        if (f.status != "found" && f.status != "rescued" && f.status != "given" && f.status != "missing")
          throw std::invalid_argument("view " + v.name + ": status '" + f.status + "'");
        if ((f.status == "missing") != (f.candidate < 0) || f.candidate >= int(v.candidates.size()))
          throw std::invalid_argument("view " + v.name + ", ball " + out.listed[b].name + ": candidate " +
                                      std::to_string(f.candidate) + " does not fit status " + f.status);
        v.balls.push_back(f);
      }
      out.views.push_back(std::move(v));
    }
    return out;
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(what + ": not an rsibr balls file: " + json_error_text(e));
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(what + ": " + e.what());
  }
}

}  // namespace rsibr
