// The page viewer's file (runtime/web_viewer_page.h), without a browser: it carries the desktop
// viewer's shader source itself (one rule), its data parse as JSON whatever the strings hold, and
// a set brighter than half floats hold is scaled into range, never written as infinities. The
// drawing itself is tested in headless Chromium against rsibr render (tests/viewer/web_viewer_test.py).
#include "runtime/web_viewer_page.h"

#include "analytic_map_set.h"
#include "core/sphere_mesh.h"
#include "runtime/map_shader.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace rsibr {
namespace {

MapSet bright_set(float peak) {
  MapSet set = testing::analytic_map_set(ViewSet::icosahedron(), 16, 16, "mirror",
                                         [](const Mat3& T, const Vec2& xy) { return Vec3(0.5, 0.25, xy.x() + 1.0); });
  set.views[3].rgb.at<cv::Vec3f>(8, 8)[1] = peak;
  return set;
}

nlohmann::json page_data(const std::string& html) {
  const std::string open = "<script type=\"application/json\" id=\"rsibr-data\">";
  const std::size_t a = html.find(open), b = html.find("</script>", a);
  EXPECT_NE(a, std::string::npos);
  return nlohmann::json::parse(html.substr(a + open.size(), b - a - open.size()));
}

WebViewerPage page_of(const MapSet& set, const Mesh& mesh) {
  WebViewerPage p;
  p.maps = &set;
  p.mesh = &mesh;
  p.camera = look_at(Vec3(0, 0, 4), Vec3::Zero(), Vec3(0, 1, 0), 40, 64, 48);
  p.title = "a <title> & \"quotes\" </script>";
  return p;
}

TEST(WebViewerPage, CarriesTheDesktopViewersShaderAsGlslEs3) {
  const MapSet set = bright_set(1.f);
  const Mesh mesh = sphere_mesh(Eigen::Vector3f::Zero(), 1.f, 8, 16);
  const std::string html = web_viewer_page(page_of(set, mesh));
  const nlohmann::json d = page_data(html);
  const std::string fs = d["fragment_shader"], vs = d["vertex_shader"];
  EXPECT_EQ(fs.rfind("#version 300 es\n", 0), 0u);
  EXPECT_NE(fs.find(kMeshFragmentShader), std::string::npos);
  EXPECT_EQ(fs, webgl2_fragment_shader());
  EXPECT_EQ(vs, webgl2_vertex_shader());
  EXPECT_NE(vs.find("uniform mat3 uCamFromWorld;"), std::string::npos);
  EXPECT_EQ(vs.find("#version 330"), std::string::npos);
  EXPECT_EQ(d["sets"].size(), 1u);
  EXPECT_EQ(d["sets"][0]["maps"]["views"], 12);
  EXPECT_EQ(d["scale"], 1.0);
  EXPECT_EQ(d["mesh"]["count"], mesh.triangles.size() * 3);
  // The title is escaped where it is HTML; no "</script>" ends the data early.
  EXPECT_NE(html.find("a &lt;title&gt; &amp; &quot;quotes&quot; &lt;/script&gt;"), std::string::npos);
}

TEST(WebViewerPage, ASetBrighterThanHalfFloatsIsScaledByAPowerOfTwo) {
  const MapSet set = bright_set(1e6f);
  const Mesh mesh = sphere_mesh(Eigen::Vector3f::Zero(), 1.f, 8, 16);
  const nlohmann::json d = page_data(web_viewer_page(page_of(set, mesh)));
  const double scale = d["scale"];
  EXPECT_EQ(scale, 32.0);  // 1e6 / 32 = 31250 <= 6e4 < 1e6 / 16
}

TEST(WebViewerPage, TwoSetsShareOneScaleForTheirWipe) {
  const MapSet dim = bright_set(1.f), bright = bright_set(1e6f);
  const Mesh mesh = sphere_mesh(Eigen::Vector3f::Zero(), 1.f, 8, 16);
  WebViewerPage p = page_of(dim, mesh);
  p.maps2 = &bright;
  p.names[0] = "captured", p.names[1] = "computed";
  const std::string html = web_viewer_page(p);
  const nlohmann::json d = page_data(html);
  EXPECT_EQ(d["sets"].size(), 2u);
  EXPECT_EQ(d["scale"], 32.0);
  EXPECT_NE(html.find("captured &#8592; wipe &#8594; computed"), std::string::npos);
}

TEST(WebViewerPage, NoMapsOrMeshIsAnError) {
  WebViewerPage p;
  EXPECT_THROW(web_viewer_page(p), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
