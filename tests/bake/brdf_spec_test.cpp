// BRDF specs: parsing, loud validation with key paths, and round trips of spec().
#include "bake/brdf_spec.h"

#include "core/test_data.h"
#include "tests/bake/brdf_cases.h"

#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

namespace rsibr {
namespace {

// The message of the std::invalid_argument that parsing `text` throws ("" if none).
std::string error_of(const std::string& text) {
  try {
    parse_brdf(text);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

bool starts_with(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

TEST(BrdfSpec, ParsesTheDocumentedExamples) {
  auto g = parse_brdf("{type: ggx, roughness: 0.3, fresnel: {type: conductor, eta: [0.2,0.9,1.1], k: [3.9,2.4,2.2]}}");
  EXPECT_EQ(g->central_direction(), CentralDirection::Mirror);
  auto l = parse_brdf("{type: lambert, albedo: [0.18,0.18,0.18]}");
  EXPECT_EQ(l->albedo(Vec3(0, 0, 1)), Vec3::Constant(0.18));
  auto c = parse_brdf(
      "type: clearcoat\n"
      "coat: {ior: 1.5, roughness: 0.05}\n"
      "flakes: {coverage: 0.3, roughness: 0.25, fresnel: {type: schlick, f0: [0.9, 0.8, 0.6]}}\n"
      "base: {albedo: [0.5, 0.05, 0.05]}\n");
  EXPECT_GT(c->albedo(Vec3(0, 0, 1)).x(), 0.1);
  EXPECT_NO_THROW(parse_brdf("{type: phong, albedo: [1, 1, 1], exponent: 20}"));
  EXPECT_NO_THROW(parse_brdf("{type: blinn_phong, albedo: [1, 1, 1], exponent: 20}"));
  EXPECT_NO_THROW(parse_brdf("{type: ggx, roughness: 1, fresnel: {type: none}}"));
  EXPECT_NO_THROW(parse_brdf("{type: ggx, roughness: 0.01, fresnel: {type: dielectric, ior: 1.5}}"));
}

TEST(BrdfSpec, SpecParsingRejectsUnknownKeys) {
  EXPECT_TRUE(starts_with(
      error_of("{type: ggx, roughness: 0.3, fresnel: {type: conductor, eta: [1,1,1], k: [1,1,1], etaa: 2}}"),
      "brdf.fresnel.etaa: unknown key"));
  EXPECT_TRUE(
      starts_with(error_of("{type: lambert, albedo: [0.1,0.1,0.1], roughness: 0.3}"), "brdf.roughness: unknown key"));
  EXPECT_TRUE(starts_with(error_of("{type: clearcoat, coat: {ior: 1.5, roughness: 0.1, thickness: 1}, "
                                   "flakes: {coverage: 0.3, roughness: 0.2, fresnel: {type: none}}, "
                                   "base: {albedo: [0.5,0.5,0.5]}}"),
                          "brdf.coat.thickness: unknown key"));
  EXPECT_TRUE(starts_with(error_of("{type: velvet}"), "brdf.type: unknown type 'velvet'"));
  EXPECT_TRUE(starts_with(error_of("{type: ggx, roughness: 0.3, fresnel: {type: magic}}"),
                          "brdf.fresnel.type: unknown type 'magic'"));
}

TEST(BrdfSpec, SpecParsingRejectsWrongTypes) {
  EXPECT_TRUE(starts_with(error_of("{type: ggx, roughness: rough, fresnel: {type: none}}"),
                          "brdf.roughness: expected a number"));
  EXPECT_TRUE(starts_with(error_of("{type: lambert, albedo: 0.5}"), "brdf.albedo: expected a sequence of 3 numbers"));
  EXPECT_TRUE(
      starts_with(error_of("{type: lambert, albedo: [0.5, 0.5]}"), "brdf.albedo: expected a sequence of 3 numbers"));
  EXPECT_TRUE(starts_with(error_of("{type: lambert, albedo: [0.5, x, 0.5]}"), "brdf.albedo[1]: expected a number"));
  EXPECT_TRUE(starts_with(error_of("{type: ggx, roughness: 0.3, fresnel: 3}"), "brdf.fresnel: expected a mapping"));
  EXPECT_TRUE(starts_with(error_of("{type: ggx, roughness: [0.3], fresnel: {type: none}}"),
                          "brdf.roughness: expected a number"));
  EXPECT_TRUE(starts_with(error_of("[1, 2]"), "brdf: expected a mapping"));
  EXPECT_TRUE(starts_with(error_of(""), "brdf: expected a mapping"));
  EXPECT_TRUE(starts_with(error_of("{type: [ggx]}"), "brdf.type: expected a string"));
  const std::string syntax = error_of("{type: ggx, roughness: 0.3");
  EXPECT_TRUE(starts_with(syntax, "brdf:1:") && syntax.find("invalid YAML") != std::string::npos) << syntax;
}

TEST(BrdfSpec, AliasCyclesInAClearCoatOrALobeAreErrorsNotCrashes) {
  for (const char* text : {"&c {type: clearcoat, coat: *c}", "&g {type: ggx, roughness: 0.3, fresnel: *g}",
                           "{type: ggx, roughness: 0.3, fresnel: &f {type: schlick, f0: [*f, 1, 1]}}"})
    EXPECT_NE(error_of(text).find("cycle"), std::string::npos) << text << " -> " << error_of(text);
}

TEST(BrdfSpec, SpecParsingRejectsMissingAndOutOfRangeValues) {
  EXPECT_TRUE(starts_with(error_of("{albedo: [1,1,1]}"), "brdf.type: missing"));
  EXPECT_TRUE(starts_with(error_of("{type: ggx, fresnel: {type: none}}"), "brdf.roughness: missing"));
  EXPECT_TRUE(
      starts_with(error_of("{type: ggx, roughness: 0, fresnel: {type: none}}"), "brdf.roughness: must be in (0,1]"));
  EXPECT_TRUE(
      starts_with(error_of("{type: ggx, roughness: 1.5, fresnel: {type: none}}"), "brdf.roughness: must be in (0,1]"));
  EXPECT_TRUE(
      starts_with(error_of("{type: ggx, roughness: .nan, fresnel: {type: none}}"), "brdf.roughness: must be finite"));
  EXPECT_TRUE(starts_with(error_of("{type: lambert, albedo: [0.5, 1.2, 0.5]}"), "brdf.albedo[1]: must be in [0,1]"));
  EXPECT_TRUE(starts_with(error_of("{type: lambert, albedo: [-0.1, 0.2, 0.5]}"), "brdf.albedo[0]: must be in [0,1]"));
  EXPECT_TRUE(
      starts_with(error_of("{type: phong, albedo: [1,1,1], exponent: 0}"), "brdf.exponent: must be in (0,inf)"));
  EXPECT_TRUE(starts_with(error_of("{type: ggx, roughness: 0.3, fresnel: {type: dielectric, ior: 0}}"),
                          "brdf.fresnel.ior: must be in (0,inf)"));
  EXPECT_TRUE(
      starts_with(error_of("{type: ggx, roughness: 0.3, fresnel: {type: conductor, eta: [1,1,1], k: [1,-1,1]}}"),
                  "brdf.fresnel.k[1]: must be in [0,inf)"));
  EXPECT_TRUE(starts_with(error_of("{type: clearcoat, coat: {ior: 1.0, roughness: 0.1}, "
                                   "flakes: {coverage: 0.3, roughness: 0.2, fresnel: {type: none}}, "
                                   "base: {albedo: [0.5,0.5,0.5]}}"),
                          "brdf.coat.ior: must be in (1,inf)"));
  EXPECT_TRUE(starts_with(error_of("{type: clearcoat, coat: {ior: 1.5, roughness: 0.1}, "
                                   "flakes: {coverage: 2, roughness: 0.2, fresnel: {type: none}}, "
                                   "base: {albedo: [0.5,0.5,0.5]}}"),
                          "brdf.flakes.coverage: must be in [0,1]"));
  EXPECT_TRUE(
      starts_with(error_of("{type: clearcoat, coat: {ior: 1.5, roughness: 0.1}, base: {albedo: [0.5,0.5,0.5]}}"),
                  "brdf.flakes: missing"));
}

TEST(BrdfSpec, SpecRoundTrips) {
  auto cases = test::sampler_cases();
  cases.push_back({"ggx_schlick", test::ggx(0.123456789, std::make_shared<SchlickFresnel>(Vec3(0.1, 0.2, 1.0 / 3)))});
  cases.push_back({"ggx_dielectric", test::ggx(1.0, std::make_shared<DielectricFresnel>(1.0 / 1.33))});
  cases.push_back({"ggx_none", test::ggx(1e-3, std::make_shared<NoFresnel>())});
  std::mt19937_64 rng(3);
  for (const auto& c : cases) {
    const std::string text = c.brdf->spec();
    EXPECT_EQ(text.find('\n'), std::string::npos) << text;
    std::unique_ptr<Brdf> back;
    ASSERT_NO_THROW(back = parse_brdf(text)) << text;
    EXPECT_EQ(back->spec(), text);
    for (int i = 0; i < 50; ++i) {
      const Vec3 wo = test::random_upper(rng), wi = test::random_upper(rng);
      EXPECT_EQ(back->eval(wo, wi), c.brdf->eval(wo, wi)) << text;  // bit-exact parameters
    }
  }
}

TEST(BrdfSpec, LoadBrdfNamesTheFile) {
  testing::TempDir dir;
  const std::string good = dir.file("paint.yaml"), bad = dir.file("bad.yaml"), broken = dir.file("broken.yaml");
  std::ofstream(good) << "type: ggx\nroughness: 0.2\nfresnel:\n  type: schlick\n  f0: [0.04, 0.04, 0.04]\n";
  std::ofstream(bad) << "type: ggx\nroughness: 0.2\nfresnel: {type: schlick, f00: [0.04, 0.04, 0.04]}\n";
  std::ofstream(broken) << "type: ggx\nroughness: [0.2\n";
  EXPECT_NO_THROW(load_brdf(good));
  const auto message = [](const std::string& path) -> std::string {
    try {
      load_brdf(path);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_TRUE(starts_with(message(bad), bad + ": brdf.fresnel.f00: unknown key")) << message(bad);
  EXPECT_TRUE(starts_with(message(broken), broken + ":")) << message(broken);
  EXPECT_TRUE(starts_with(message(dir.file("missing.yaml")), dir.file("missing.yaml") + ": cannot read"));
  // One line each.
  EXPECT_EQ(message(bad).find('\n'), std::string::npos);
  EXPECT_EQ(message(broken).find('\n'), std::string::npos);
}

}  // namespace
}  // namespace rsibr
