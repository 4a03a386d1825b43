// SPDX-License-Identifier: MIT
// The helpers viz's renderers share (viz/src/chart_util.hpp): HTML text, page head, ticks.
#include "chart_util.hpp"

#include <gtest/gtest.h>

namespace tgraph::viz::detail {
namespace {

TEST(ChartUtil, EscapesTheFourHtmlSpecialCharacters) {
  EXPECT_EQ(escape("a<b>&\"c'"), "a&lt;b&gt;&amp;&quot;c'");
  EXPECT_EQ(escape(""), "");
}

TEST(ChartUtil, ScriptJsonCannotCloseItsScriptElement) {
  const nlohmann::json j = {{"t", "</script><script>alert(1)</script>"}};
  const std::string s = script_json(j);
  EXPECT_EQ(s.find("</"), std::string::npos) << s;
  EXPECT_EQ(nlohmann::json::parse(s), j);  // "<\/" is the same string to a JSON reader
}

TEST(ChartUtil, TickStepsAreOneTwoOrFiveTimesAPowerOfTen) {
  EXPECT_EQ(tick_step(10, 10), 1);
  EXPECT_EQ(tick_step(15, 10), 2);
  EXPECT_EQ(tick_step(30, 10), 5);
  EXPECT_EQ(tick_step(0.7, 6), 0.2);
  EXPECT_EQ(tick_step(0, 10), 1);  // an empty range
  EXPECT_EQ(decimals_for(1), 0);
  EXPECT_EQ(decimals_for(0.2), 1);
  EXPECT_EQ(decimals_for(0.05), 2);
  EXPECT_EQ(fixed(2.345, 1), "2.3");
}

TEST(ChartUtil, PageHeadEscapesTheTitleAndInlinesTheLibrariesInOrder) {
  const std::string h = page_head("a <b>", "body{}", {"vega", "vega-lite"});
  EXPECT_EQ(h.rfind("<!doctype html>", 0), 0u);
  EXPECT_NE(h.find("<title>a &lt;b&gt;</title><style>body{}</style>"), std::string::npos);
  const auto vega = h.find("<script>/* vega */"), lite = h.find("<script>/* vega-lite */");
  ASSERT_NE(vega, std::string::npos);
  ASSERT_NE(lite, std::string::npos);
  EXPECT_LT(vega, lite);
  EXPECT_GT(lite - vega, 1000u);  // the minified bundle itself
  EXPECT_LT(h.find(kErrorHookScript), vega);  // the error hook comes first
  EXPECT_EQ(h.substr(h.size() - 13), "</head><body>");
}

}  // namespace
}  // namespace tgraph::viz::detail
