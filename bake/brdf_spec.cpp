#include "bake/brdf_spec.h"

#include "bake/blinn_phong.h"
#include "bake/brdf_lobes.h"
#include "bake/clear_coat.h"
#include "bake/ggx.h"
#include "bake/lambert.h"
#include "bake/phong.h"
#include "formats/yaml_spec.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace rsibr {

namespace {

using MapSpec = YamlMap;

[[noreturn]] void fail(const std::string& path, const std::string& what) { spec_fail(path, what); }

constexpr double kInf = std::numeric_limits<double>::infinity();

double in_range(double x, const std::string& path, double lo, bool lo_open, double hi, bool hi_open) {
  return spec_in_range(x, path, lo, lo_open, hi, hi_open);
}
double roughness(const MapSpec& m) { return m.number_in("roughness", 0, true, 1, false); }
double positive(const MapSpec& m, const std::string& key) { return m.positive(key); }
Vec3 rgb_in(const MapSpec& m, const std::string& key, double lo, bool lo_open, double hi, bool hi_open) {
  const Vec3 c = m.vec3(key);
  for (int i = 0; i < 3; ++i) in_range(c[i], m.at(key) + "[" + std::to_string(i) + "]", lo, lo_open, hi, hi_open);
  return c;
}
Vec3 unit_rgb(const MapSpec& m, const std::string& key) { return rgb_in(m, key, 0, false, 1, false); }

std::string type_of(const YAML::Node& node, const std::string& path, const std::vector<std::string>& types) {
  return spec_type(node, path, types);
}

}  // namespace

std::shared_ptr<const Fresnel> make_fresnel(const YAML::Node& spec, const std::string& path) {
  const std::string type = type_of(spec, path, {"none", "schlick", "dielectric", "conductor"});
  if (type == "none") {
    MapSpec m(spec, path, {"type"});
    return std::make_shared<NoFresnel>();
  }
  if (type == "schlick") {
    MapSpec m(spec, path, {"type", "f0"});
    return std::make_shared<SchlickFresnel>(unit_rgb(m, "f0"));
  }
  if (type == "dielectric") {
    MapSpec m(spec, path, {"type", "ior"});
    return std::make_shared<DielectricFresnel>(positive(m, "ior"));
  }
  MapSpec m(spec, path, {"type", "eta", "k"});
  return std::make_shared<ConductorFresnel>(rgb_in(m, "eta", 0, true, kInf, true),
                                            rgb_in(m, "k", 0, false, kInf, true));
}

std::unique_ptr<Brdf> make_brdf(const YAML::Node& spec, const std::string& path) {
  const std::string type = type_of(spec, path, {"lambert", "phong", "blinn_phong", "ggx", "clearcoat", "lobe"});
  if (type == "lobe") {
    MapSpec m(spec, path, {"type", "part", "of"});
    const std::string part = m.string("part");
    if (part != "normal" && part != "mirror") fail(m.at("part"), "expected normal or mirror, got '" + part + "'");
    std::shared_ptr<const Brdf> parent = make_brdf(m.get("of"), m.at("of"));
    if (!parent->has_lobe(central_direction_from_string(part)))
      fail(m.at("part"), "the BRDF in 'of' has no " + part + " lobe");
    return std::make_unique<BrdfLobe>(std::move(parent), central_direction_from_string(part));
  }
  if (type == "lambert") {
    MapSpec m(spec, path, {"type", "albedo"});
    return std::make_unique<LambertBrdf>(unit_rgb(m, "albedo"));
  }
  if (type == "phong" || type == "blinn_phong") {
    MapSpec m(spec, path, {"type", "albedo", "exponent"});
    const Vec3 rho = unit_rgb(m, "albedo");
    const double e = positive(m, "exponent");
    if (type == "phong") return std::make_unique<PhongBrdf>(rho, e);
    return std::make_unique<BlinnPhongBrdf>(rho, e);
  }
  if (type == "ggx") {
    MapSpec m(spec, path, {"type", "roughness", "fresnel"});
    const double a = roughness(m);
    return std::make_unique<GgxBrdf>(a, make_fresnel(m.get("fresnel"), m.at("fresnel")));
  }
  MapSpec m(spec, path, {"type", "coat", "flakes", "base"});
  ClearCoatParams p;
  {
    MapSpec coat(m.get("coat"), m.at("coat"), {"ior", "roughness"});
    p.coat_ior = in_range(coat.number("ior"), coat.at("ior"), 1, true, kInf, true);
    p.coat_roughness = roughness(coat);
  }
  {
    MapSpec flakes(m.get("flakes"), m.at("flakes"), {"coverage", "roughness", "fresnel"});
    p.flake_coverage = in_range(flakes.number("coverage"), flakes.at("coverage"), 0, false, 1, false);
    p.flake_roughness = roughness(flakes);
    p.flake_fresnel = make_fresnel(flakes.get("fresnel"), flakes.at("fresnel"));
  }
  {
    MapSpec base(m.get("base"), m.at("base"), {"albedo"});
    p.base_albedo = unit_rgb(base, "albedo");
  }
  return std::make_unique<ClearCoatBrdf>(std::move(p));
}

std::unique_ptr<Brdf> parse_brdf(const std::string& yaml_text) { return make_brdf(parse_yaml(yaml_text, "brdf")); }

std::unique_ptr<Brdf> load_brdf(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::invalid_argument(file.string() + ": cannot read BRDF spec");
  std::ostringstream text;
  text << in.rdbuf();
  const YAML::Node node = parse_yaml(text.str(), file.string());
  try {
    return make_brdf(node);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(file.string() + ": " + e.what());
  }
}

}  // namespace rsibr
