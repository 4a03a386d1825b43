// SPDX-License-Identifier: MIT
// Timelines (parsing, Gantt rendering, Chrome flows) and the HTML report.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "tgraph/capture/recorder.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/samples/scene.hpp"
#include "tgraph/viz/report.hpp"
#include "tgraph/viz/timeline.hpp"

namespace tgraph::viz {
namespace {

// Two threads, two steps: thread 1 waits for thread 0's "a" in step 0.
const char* kTimeline = R"({"threads":2,"steps":2,"tasks":[
 {"step":0,"thread":0,"task":0,"origin":0,"kind":"a","iteration":0,"start_ns":0,"end_ns":1000},
 {"step":0,"thread":1,"task":1,"origin":1,"kind":"b","iteration":0,"start_ns":1200,"end_ns":2000},
 {"step":0,"thread":0,"task":2,"origin":2,"kind":"c","iteration":1,"start_ns":1000,"end_ns":1500},
 {"step":1,"thread":0,"task":0,"origin":0,"kind":"a","iteration":0,"start_ns":0,"end_ns":500},
 {"step":1,"thread":1,"task":3,"origin":null,"kind":"reduce","iteration":0,"start_ns":100,"end_ns":300}],
 "waits":[{"step":0,"thread":1,"task":1,"start_ns":100,"end_ns":1100,"parked":false}]})";

TEST(Timeline, ParsesAndLaysStepsEndToEnd) {
  const Timeline t = parse_timeline(kTimeline, "t.json");
  EXPECT_EQ(t.threads, 2u);
  ASSERT_EQ(t.tasks.size(), 5u);
  EXPECT_FALSE(t.tasks[4].origin.has_value());
  EXPECT_EQ(t.step_offsets(), (std::vector<std::int64_t>{0, 2000}));
}

TEST(Timeline, RejectsMalformedInputNamingTheFile) {
  for (const char* bad : {"", "[]", R"({"tasks":3})", R"({"tasks":[{"step":0}]})",
                          R"({"threads":1,"tasks":[{"step":0,"thread":3,"task":0,"start_ns":0,"end_ns":1}]})",
                          R"({"tasks":[{"step":0,"thread":0,"task":0,"start_ns":5,"end_ns":1}]})",
                          R"({"tasks":[{"step":-1,"thread":0,"task":0,"start_ns":0,"end_ns":1}]})"}) {
    try {
      parse_timeline(bad, "bad.json");
      ADD_FAILURE() << "accepted: " << bad;
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("bad.json: ", 0), 0u) << e.what();
    }
  }
}

TEST(Timeline, SelectsAStepRange) {
  const Timeline t = parse_timeline(kTimeline, "t.json");
  EXPECT_EQ(parse_step_range("1:"), (std::pair<std::uint32_t, std::uint32_t>{1, 0xffffffffu}));
  EXPECT_EQ(parse_step_range("0:0"), (std::pair<std::uint32_t, std::uint32_t>{0, 0}));
  EXPECT_EQ(select_steps(t, 1, 1).tasks.size(), 2u);
  EXPECT_THROW(select_steps(t, 5, 9), UsageError);
  EXPECT_THROW(parse_step_range("2:1"), UsageError);
  EXPECT_THROW(parse_step_range("x"), UsageError);
}

TEST(Timeline, FlowGoesFromTheReleasingTaskToTheWait) {
  const Timeline t = parse_timeline(kTimeline, "t.json");
  const std::vector<TimelineFlow> flows = timeline_flows(t);
  ASSERT_EQ(flows.size(), 1u);
  EXPECT_EQ(flows[0].from_task, 0u);  // "a" on thread 0 ended at 1000, inside [100, 1100]
  EXPECT_EQ(flows[0].to_wait, 0u);
  const nlohmann::json chrome = nlohmann::json::parse(chrome_trace(t));
  int starts = 0, finishes = 0, waits = 0;
  for (const auto& e : chrome["traceEvents"]) {
    if (e["ph"] == "s") {
      ++starts;
      EXPECT_EQ(e["tid"], 0);
      EXPECT_DOUBLE_EQ(e["ts"].get<double>(), 0.999);
    }
    if (e["ph"] == "f") {
      ++finishes;
      EXPECT_EQ(e["tid"], 1);
      EXPECT_EQ(e["bp"], "e");
    }
    if (e["ph"] == "X" && e["cat"] == "wait") ++waits;
  }
  EXPECT_EQ(starts, 1);
  EXPECT_EQ(finishes, 1);
  EXPECT_EQ(waits, 1);
}

TEST(Timeline, RendersSvgAndPngWithCairo) {
  const Timeline t = parse_timeline(kTimeline, "t.json");
  const std::string svg = render_timeline(t, TimelineFormat::kSvg, "test");
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  const std::string png = render_timeline(t, TimelineFormat::kPng, "test");
  ASSERT_GT(png.size(), 8u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
  EXPECT_THROW(timeline_format_of("r.pdf"), UsageError);
}

TEST(Report, PageIsSelfContainedWithOneContainerPerChart) {
  auto scene = samples::make_scene("fig2", {});
  capture::Recorder rec(capture::Mode::kCapture);
  Trace trace;
  for (int s = 0; s < 3; ++s) {
    scene->step(rec);
    trace.steps.push_back(rec.end_step());
  }
  ReportContent c = report_content(trace, "fig2.tgt", nullptr, 1);
  MethodRow row;
  row.method = "metis";
  row.k = 2;
  row.partitioned = true;
  row.partition_ms = 0.123456;
  row.imbalance = 1.0414;
  row.predicted_speedup = 1.77169;
  row.speedup = 1.4;
  row.measured_ms = 4.47482;
  c.rows.push_back(row);
  c.series.push_back({"metis", 2, {0.1, 0.2, 0.3}, {0, 1, 0}});
  c.timeline = parse_timeline(kTimeline, "t.json");
  const std::string html = report_html(c);
  for (const char* id : {"chart-speedup", "chart-methods", "chart-partition-time", "chart-migrations", "chart-timeline"})
    EXPECT_NE(html.find(std::string("id=\"") + id + "\""), std::string::npos) << id;
  EXPECT_EQ(html.find("<script src"), std::string::npos);
  EXPECT_EQ(html.find("cdn"), std::string::npos);
  EXPECT_NE(html.find("vegaEmbed"), std::string::npos);
  EXPECT_NE(html.find("<td>4.47</td>"), std::string::npos);  // rounded, not 4.47482
  EXPECT_NE(html.find("<td>1.77</td>"), std::string::npos);
  EXPECT_EQ(html.find("4.47482"), std::string::npos);
  EXPECT_NE(html.find("<svg"), std::string::npos);  // the step graph
  EXPECT_EQ(round3(0.0123456), "0.0123");
  EXPECT_EQ(round3(1234.6), "1235");
  EXPECT_EQ(round3(4.47482), "4.47");
}

TEST(Report, RejectsFilesOfAnotherKind) {
  ReportContent c;
  EXPECT_THROW(add_compare_json(c, R"({"tasks":[]})", "c.json"), InputError);
  EXPECT_THROW(add_replay_json(c, R"({"rows":[]})", "r.json"), InputError);
  add_replay_json(c, kTimeline, "t.json");
  EXPECT_TRUE(c.timeline.has_value());
}

}  // namespace
}  // namespace tgraph::viz
