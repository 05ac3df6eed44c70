// Pieces of the report (pipeline/html_report.h): base64 against RFC 4648's vectors, escaping, plots.
#include "pipeline/html_report.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rsibr {
namespace {

std::vector<unsigned char> bytes(const std::string& s) { return {s.begin(), s.end()}; }

TEST(HtmlReport, Base64MatchesRfc4648TestVectors) {
  EXPECT_EQ(base64_encode(bytes("")), "");
  EXPECT_EQ(base64_encode(bytes("f")), "Zg==");
  EXPECT_EQ(base64_encode(bytes("fo")), "Zm8=");
  EXPECT_EQ(base64_encode(bytes("foo")), "Zm9v");
  EXPECT_EQ(base64_encode(bytes("foob")), "Zm9vYg==");
  EXPECT_EQ(base64_encode(bytes("fooba")), "Zm9vYmE=");
  EXPECT_EQ(base64_encode(bytes("foobar")), "Zm9vYmFy");
  EXPECT_EQ(base64_encode({0xff, 0xfe, 0x00}), "//4A");
}

TEST(HtmlReport, EscapingRemovesMarkup) {
  EXPECT_EQ(html_escape("<a href=\"x\">&</a>"), "&lt;a href=&quot;x&quot;&gt;&amp;&lt;/a&gt;");
}

TEST(HtmlReport, PlotMapsTheDataRangeOntoTheFrameAndSkipsNonFinite) {
  PlotSeries s{"curve", "#d33", {0, 1, 2}, {0, NAN, 4}};
  const std::string svg = svg_line_plot({s}, "x", "y", 200, 100);
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  // Frame: left 60, right 200-16, top 12, bottom 100-40: (0,0) -> (60,60), (2,4) -> (184,12).
  EXPECT_NE(svg.find("points=\"60,60 184,12 \""), std::string::npos) << svg;
  EXPECT_EQ(svg.find("nan"), std::string::npos);
}

}  // namespace
}  // namespace rsibr
