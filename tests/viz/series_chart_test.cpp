// SPDX-License-Identifier: MIT
// Series charts: the Vega-Lite specification, the cairo pictures and the HTML page.
#include "tgraph/viz/series_chart.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace tgraph::viz {
namespace {

using nlohmann::json;

SeriesChart speedup_chart() {
  SeriesChart c;
  c.title = "Speed-up";
  c.subtitle = "two methods";
  c.x_title = "threads";
  c.y_title = "speed-up";
  c.log2_x = true;
  c.series = {{"ideal", SeriesKind::kReference, 0, {{1, 1}, {64, 64}}},
              {"owner", SeriesKind::kMeasured, 0, {{1, 0.98}, {2, 1.9}}},
              {"owner (predicted)", SeriesKind::kPredicted, 0, {{1, 1}, {2, 1.95}, {64, 40}}},
              {"worksteal", SeriesKind::kMeasured, 1, {{1, 0.9}, {2, 1.2}}}};
  c.marks = {{2, "2 cores"}};
  return c;
}

// The data rows of one series in a specification.
std::vector<json> rows_of(const json& spec, const std::string& series) {
  std::vector<json> out;
  for (const json& v : spec["data"]["values"])
    if (v["series"] == series) out.push_back(v);
  return out;
}

TEST(SeriesChart, SpecKeepsEachSeriesKindAndPoints) {
  const json spec = json::parse(series_chart_spec(speedup_chart()));
  EXPECT_EQ(spec["$schema"], "https://vega.github.io/schema/vega-lite/v5.json");
  const std::vector<json> predicted = rows_of(spec, "owner (predicted)");
  ASSERT_EQ(predicted.size(), 3u);
  for (const json& v : predicted) EXPECT_EQ(v["kind"], "predicted");
  EXPECT_EQ(predicted[2]["x"], 64);
  EXPECT_EQ(predicted[2]["y"], 40);
  for (const json& v : rows_of(spec, "owner")) EXPECT_EQ(v["kind"], "measured");
  for (const json& v : rows_of(spec, "ideal")) EXPECT_EQ(v["kind"], "reference");
  // Measured and predicted of one method share a colour; references are black.
  const json& colour = spec["layer"][0]["encoding"]["color"]["scale"];
  ASSERT_EQ(colour["domain"].size(), 4u);
  EXPECT_EQ(colour["range"][0], "#000000");
  EXPECT_EQ(colour["range"][1], colour["range"][2]);
  EXPECT_NE(colour["range"][1], colour["range"][3]);
}

TEST(SeriesChart, Log2AxisTicksArePowersOfTwoCoveringTheData) {
  const json spec = json::parse(series_chart_spec(speedup_chart()));
  const json& x = spec["layer"][0]["encoding"]["x"];
  EXPECT_EQ(x["scale"]["type"], "log");
  EXPECT_EQ(x["axis"]["values"], json({1, 2, 4, 8, 16, 32, 64}));
  SeriesChart c = speedup_chart();
  c.log2_y = true;
  const json y = json::parse(series_chart_spec(c))["layer"][0]["encoding"]["y"];
  // 0.9 is the smallest y: the axis starts at 0.5.
  EXPECT_EQ(y["axis"]["values"].front(), 0.5);
  EXPECT_EQ(y["axis"]["values"].back(), 64);
}

TEST(SeriesChart, DropsPointsALogAxisCannotShow) {
  SeriesChart c = speedup_chart();
  c.log2_y = true;
  c.series[1].points.push_back({4, 0.0});
  c.series[1].points.push_back({0, 1.0});
  c.log2_x = true;
  const json spec = json::parse(series_chart_spec(c));
  EXPECT_EQ(rows_of(spec, "owner").size(), 2u);
}

TEST(SeriesChart, RendersSvgAndPng) {
  const std::string svg = render_series_chart(speedup_chart(), TimelineFormat::kSvg);
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  const std::string png = render_series_chart(speedup_chart(), TimelineFormat::kPng);
  ASSERT_GT(png.size(), 8u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
  // An empty chart still draws (axes only).
  EXPECT_NE(render_series_chart(SeriesChart{}, TimelineFormat::kSvg).find("<svg"),
            std::string::npos);
}

TEST(SeriesChart, PageEscapesTextAndEmbedsOneSpecPerChart) {
  SeriesPage page;
  page.title = "a <b> & c";
  page.facts = {{"machine", "2 cores"}};
  page.tables = {{"caption", {"method", "speed-up"}, {{"owner", "1.9"}, {"x</script>", ""}}}};
  page.charts = {speedup_chart(), speedup_chart()};
  const std::string html = series_page_html(page);
  EXPECT_NE(html.find("<title>a &lt;b&gt; &amp; c</title>"), std::string::npos);
  EXPECT_EQ(html.find("x</script>"), std::string::npos);
  EXPECT_NE(html.find("<td>&ndash;</td>"), std::string::npos);  // the empty cell
  const std::string open = "<script type=\"application/json\" id=\"tgraph-specs\">";
  const auto at = html.find(open);
  ASSERT_NE(at, std::string::npos);
  const auto end = html.find("</script>", at);
  std::string text = html.substr(at + open.size(), end - at - open.size());
  const json specs = json::parse(text);
  EXPECT_EQ(specs.size(), 2u);
  EXPECT_TRUE(specs.contains("chart-0") && specs.contains("chart-1"));
}

}  // namespace
}  // namespace tgraph::viz
