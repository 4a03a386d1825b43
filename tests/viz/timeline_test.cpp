// SPDX-License-Identifier: MIT
// Timelines (Gantt rendering, Chrome flows, step ranges) and the HTML report; the model and
// its JSON are tested in tests/graph/timeline_test.cpp.
#include "tgraph/viz/timeline.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"
#include "tgraph/viz/report.hpp"
#include "scene_traces.hpp"

namespace tgraph::viz {
namespace {

// Two threads, two steps: thread 1 waits for thread 0's "a" in step 0 (tests/graph reads it too).
const std::string kTimeline =
    read_file_text(std::string(TGRAPH_TEST_DATA) + "/timelines/two_steps.json");

// The first `steps` steps of the fig2 scene.
Trace fig2_trace(int steps) { return testing::scene_trace("fig2", steps); }

// Tasks of `g` alternately on processors 0 and 1.
Assignment alternating(const StepGraph& g) {
  Assignment a;
  a.k = 2;
  for (TaskId t = 0; t < g.tasks.size(); ++t) a.proc.push_back(t % 2);
  return a;
}

TEST(Timeline, SelectsAStepRange) {
  const Timeline t = parse_timeline(kTimeline, "t.json");
  using Range = std::pair<std::uint32_t, std::uint32_t>;
  EXPECT_EQ(parse_step_range("1:"), (Range{1, 0xffffffffu}));
  EXPECT_EQ(parse_step_range("0:0"), (Range{0, 0}));
  EXPECT_EQ(parse_step_range(":3"), (Range{0, 3}));
  EXPECT_EQ(parse_step_range("7"), (Range{7, 7}));
  for (const char* bad : {"2:1", "x", "", "1:x", "1:2:3", "-1"})
    EXPECT_FALSE(parse_step_range(bad).has_value()) << bad;
  EXPECT_EQ(select_steps(t, 1, 1).tasks.size(), 2u);
  try {
    select_steps(t, 5, 9);
    ADD_FAILURE() << "no error";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.option(), "steps");
    EXPECT_EQ(e.problem(), "no task in steps 5 to 9 (the timeline has steps 0 to 1)");
  }
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

// One Chrome slice per task instance (its kind, thread, duration) and per wait, in order,
// thread names, and one flow arrow pair per timeline_flows() entry (`tgraph replay --chrome`:
// tests/apps/cli_test.cpp).
TEST(Timeline, ConvertsEveryEventToChromeSlices) {
  const Timeline t = parse_timeline(kTimeline, "t.json");
  const nlohmann::json chrome = nlohmann::json::parse(chrome_trace(t));
  std::size_t slices = 0, wait_slices = 0, names = 0, starts = 0, finishes = 0;
  for (const auto& e : chrome.at("traceEvents")) {
    if (e["ph"] == "X" && e["cat"] != "wait") {
      ASSERT_LT(slices, t.tasks.size());
      const TimelineTask& ev = t.tasks[slices++];
      EXPECT_EQ(e["name"], ev.kind);
      EXPECT_EQ(e["tid"], ev.thread);
      EXPECT_EQ(e["cat"], !ev.origin ? "reducer" : "task");
      EXPECT_DOUBLE_EQ(e["dur"].get<double>(), static_cast<double>(ev.end_ns - ev.start_ns) / 1000);
    }
    if (e["ph"] == "X" && e["cat"] == "wait") ++wait_slices;
    if (e["ph"] == "M") {
      EXPECT_EQ(e["args"]["name"], "thread " + std::to_string(names++));
    }
    starts += e["ph"] == "s" ? 1 : 0;
    finishes += e["ph"] == "f" ? 1 : 0;
  }
  EXPECT_EQ(slices, t.tasks.size());
  EXPECT_EQ(wait_slices, t.waits.size());
  EXPECT_EQ(names, 2u);
  EXPECT_EQ(starts, timeline_flows(t).size());
  EXPECT_EQ(starts, 1u);
  EXPECT_EQ(finishes, starts);
}

TEST(Timeline, ReadsAFileAndTitlesItByFileName) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "viz_read";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "r.json").string();
  write_file_atomic(path, kTimeline);
  const Timeline t = read_timeline(path);
  EXPECT_EQ(t.tasks.size(), 5u);
  EXPECT_EQ(timeline_title(t, path), "r.json: 2 threads, 5 task instances, 1 blocking waits");
  try {
    read_timeline((dir / "missing.json").string());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), (dir / "missing.json").string());
  }
  std::filesystem::remove_all(dir);
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
  const Trace trace = fig2_trace(3);
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
  for (const char* id : {"chart-speedup", "chart-methods", "chart-partition-time",
                         "chart-migrations", "chart-timeline"})
    EXPECT_NE(html.find(std::string("id=\"") + id + "\""), std::string::npos) << id;
  EXPECT_EQ(html.find("<script src"), std::string::npos);
  EXPECT_EQ(html.find("cdn"), std::string::npos);
  EXPECT_NE(html.find("vegaEmbed"), std::string::npos);
  EXPECT_NE(html.find("<td>4.47</td>"), std::string::npos);  // rounded, not 4.47482
  EXPECT_NE(html.find("<td>1.77</td>"), std::string::npos);
  EXPECT_EQ(html.find("4.47482"), std::string::npos);
  EXPECT_NE(html.find("<svg"), std::string::npos);  // the step graph
  // ... in a pan/zoom box bound by the inlined Panzoom, without a quotient graph here.
  EXPECT_NE(html.find("<div class=\"graph\" id=\"graph-step\"><svg"), std::string::npos);
  EXPECT_NE(html.find("Panzoom 4.6.2"), std::string::npos);  // the library's banner
  EXPECT_NE(html.find("Panzoom(svg, {canvas: true"), std::string::npos);
  EXPECT_EQ(html.find("id=\"graph-quotient\""), std::string::npos);
  EXPECT_EQ(round3(0.0123456), "0.0123");
  EXPECT_EQ(round3(1234.6), "1235");
  EXPECT_EQ(round3(4.47482), "4.47");
}

TEST(Report, FromFilesAddsTheComparisonAndReplaysAndFallsBackToStepZero) {
  const Trace trace = fig2_trace(2);
  TraceAssignment as;
  as.method = "owner";
  as.k = 2;
  for (const StepGraph& g : trace.steps) as.steps.push_back(alternating(g));
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / "viz_report";
  std::filesystem::create_directories(dir);
  const std::string compare = (dir / "c.json").string(), replay = (dir / "r.json").string();
  write_file_atomic(compare, R"({"rows":[{"method":"metis","k":2,"partition_ms":0.5,
    "imbalance":1.25,"cut_bytes":96,"migrated_tasks":3,"predicted_speedup":1.5}]})");
  write_file_atomic(replay, kTimeline);
  const ReportContent c = report_from_files(trace, "f.tgt", &as, 7, compare, {replay});
  ASSERT_EQ(c.rows.size(), 1u);
  EXPECT_EQ(c.rows[0].method, "metis");
  EXPECT_EQ(c.rows[0].cut_bytes, 96u);
  ASSERT_TRUE(c.timeline.has_value());
  EXPECT_EQ(c.timeline->tasks.size(), 5u);
  EXPECT_EQ(c.timeline_caption, "From " + replay + ".");
  // Step 7 does not exist: step 0 is drawn, coloured by the assignment's step 0.
  EXPECT_EQ(c.graph_caption.rfind("Step 0 collapsed by object", 0), 0u) << c.graph_caption;
  EXPECT_NE(c.graph_caption.find("(owner)"), std::string::npos) << c.graph_caption;
  const ReportContent plain = report_from_files(trace, "f.tgt", nullptr, 1, "", {});
  EXPECT_TRUE(plain.rows.empty());
  EXPECT_FALSE(plain.timeline.has_value());
  EXPECT_NE(plain.graph_caption.find("(no assignment: grey)"), std::string::npos);
  EXPECT_THROW(report_from_files(trace, "f.tgt", nullptr, 1, (dir / "none.json").string(), {}),
               InputError);
  std::filesystem::remove_all(dir);
}

TEST(Report, DrawsTheQuotientGraphBesideTheStepGraph) {
  const Trace trace = fig2_trace(2);
  const Assignment a = alternating(trace.steps[1]);
  ReportContent c = report_content(trace, "fig2.tgt", &a, 1, "alternate");
  EXPECT_EQ(c.graph_step, 1u);
  set_quotient(c, quotient_graph(trace.steps[1], a), "alternate");
  const std::string html = report_html(c);
  const auto step = html.find("id=\"graph-step\""), quotient = html.find("id=\"graph-quotient\"");
  ASSERT_NE(step, std::string::npos);
  ASSERT_NE(quotient, std::string::npos);
  EXPECT_LT(step, quotient);
  EXPECT_NE(html.find("quotient graph, step 1, alternate on 2 processors"), std::string::npos);
  for (const char* text : {">p0</text>", ">p1</text>"})
    EXPECT_NE(html.find(text, quotient), std::string::npos) << text;
  // The step graph keeps its edge labels as hover text: tooltips, not drawn text.
  EXPECT_NE(c.graph_caption.find("Hover a node or an edge"), std::string::npos);
  EXPECT_NE(c.graph_svg.find("xlink:title="), std::string::npos);
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
