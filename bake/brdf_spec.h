// BRDF specs: YAML text -> Brdf (bake/brdf.h). Every key is required; unknown keys, wrong types
// and out-of-range values are errors (std::invalid_argument, one line naming the key path from
// the root "brdf", e.g. "brdf.fresnel.etaa: unknown key").
//
//   {type: lambert,     albedo: [r, g, b]}                                    albedo in [0,1]
//   {type: phong,       albedo: [r, g, b], exponent: e}                       e > 0
//   {type: blinn_phong, albedo: [r, g, b], exponent: e}                       e > 0
//   {type: ggx,         roughness: a, fresnel: F}                             a (GGX alpha) in (0,1]
//   {type: clearcoat,   coat: {ior: n, roughness: a},                         n > 1
//                       flakes: {coverage: c, roughness: a, fresnel: F},      c in [0,1]
//                       base: {albedo: [r, g, b]}}
//   {type: lobe,        part: normal|mirror, of: B}                          one part of the BRDF B
//                                                                          (bake/brdf_lobes.h); B
//                                                                          must have that part
//   F = {type: none} | {type: schlick, f0: [r, g, b]} | {type: dielectric, ior: n}      n > 0
//     | {type: conductor, eta: [r, g, b], k: [r, g, b]}                                 eta > 0, k >= 0
//
// Brdf::spec() writes this format (one line, flow style, shortest round-trip numbers), so
// make_brdf(YAML::Load(b.spec())) rebuilds b exactly.
#pragma once

#include "bake/brdf.h"
#include "bake/fresnel.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <memory>
#include <string>

namespace rsibr {

// `path` names the node in error messages.
std::unique_ptr<Brdf> make_brdf(const YAML::Node& spec, const std::string& path = "brdf");
std::shared_ptr<const Fresnel> make_fresnel(const YAML::Node& spec, const std::string& path = "fresnel");

// YAML text (e.g. from Brdf::spec() or a map set's rsibr.material attribute).
std::unique_ptr<Brdf> parse_brdf(const std::string& yaml_text);

// A YAML file whose root is a BRDF spec; errors are prefixed with the file name.
std::unique_ptr<Brdf> load_brdf(const std::filesystem::path& file);

}  // namespace rsibr
