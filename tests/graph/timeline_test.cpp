// SPDX-License-Identifier: MIT
// The timeline model: its JSON writer and reader, step offsets.
#include "tgraph/graph/timeline.hpp"

#include <gtest/gtest.h>

#include <optional>
#include <tuple>
#include <vector>

#include "../scratch_dir.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/graph/file_util.hpp"

namespace tgraph {
namespace {

// Two threads, two steps: thread 1 waits for thread 0's "a" in step 0 (tests/viz reads it too).
const std::string kTimeline =
    read_file_text(std::string(TGRAPH_TEST_DATA) + "/timelines/two_steps.json");

TEST(Timeline, ParsesAndLaysStepsEndToEnd) {
  const Timeline t = parse_timeline(kTimeline, "t.json");
  EXPECT_EQ(t.threads, 2u);
  ASSERT_EQ(t.tasks.size(), 5u);
  EXPECT_FALSE(t.tasks[4].origin.has_value());
  EXPECT_EQ(t.step_offsets(), (std::vector<std::int64_t>{0, 2000}));
}

TEST(Timeline, RejectsMalformedInputNamingTheFile) {
  for (const char* bad :
       {"", "[]", R"({"tasks":3})", R"({"tasks":[{"step":0}]})",
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

TEST(Timeline, WritesWhatItReadsBack) {
  const Timeline t = parse_timeline(kTimeline, "t.json");
  EXPECT_EQ(t.steps, 2u);
  const Timeline back = parse_timeline(timeline_json(t), "back.json");
  EXPECT_EQ(back.threads, t.threads);
  EXPECT_EQ(back.steps, t.steps);
  ASSERT_EQ(back.tasks.size(), t.tasks.size());
  for (std::size_t i = 0; i < t.tasks.size(); ++i) {
    const TimelineTask &a = t.tasks[i], &b = back.tasks[i];
    EXPECT_EQ(std::tie(a.step, a.thread, a.task, a.origin, a.kind, a.iteration, a.start_ns,
                       a.end_ns),
              std::tie(b.step, b.thread, b.task, b.origin, b.kind, b.iteration, b.start_ns,
                       b.end_ns))
        << "task instance " << i;
  }
  ASSERT_EQ(back.waits.size(), 1u);
  EXPECT_EQ(back.waits[0].task, std::optional<TaskId>(1));
  EXPECT_EQ(back.waits[0].end_ns, 1100);
  EXPECT_FALSE(back.waits[0].parked);
}

TEST(Timeline, CountsStepsFromTheEventsWhenTheFileDoesNotSay) {
  const Timeline t =
      parse_timeline(R"({"tasks":[{"step":0,"thread":0,"task":0,"start_ns":0,"end_ns":7}],
                         "waits":[{"step":1,"thread":1,"start_ns":2,"end_ns":3}]})",
                     "t.json");
  EXPECT_EQ(t.steps, 2u);
  EXPECT_EQ(t.threads, 2u);
  EXPECT_EQ(t.tasks[0].kind, "task");
  EXPECT_FALSE(t.waits[0].task.has_value());
  EXPECT_EQ(t.step_offsets(), (std::vector<std::int64_t>{0, 7}));
}

// A timeline with its step's graph, written in columns, gzip-compressed and read back.
Timeline with_graph() {
  Timeline t = parse_timeline(kTimeline, "t.json");
  TimelineGraph g;
  g.kinds = {"a", "b", "c", "reduce"};
  g.data = {"x", "y"};
  g.task_kind = {0, 1, 2, 3};
  g.origin = {0, 1, 2, kNoTask};
  g.task_loop = {kNoLoop, kNoLoop, 0, kNoLoop};
  g.loops = {{2, 3}};
  g.edges = {{0, 1, 0, EdgeKind::RAW}, {1, 3, 1, EdgeKind::RAW}};
  g.carried_edges = {{2, 2, 1, EdgeKind::RAW}};
  t.graphs = {g};
  TimelineStep s;
  s.step = 0;
  s.wall_ns = 2100;
  s.record_ns = 5;
  s.partition_ns = 6;
  s.prepare_ns = 7;
  s.host_ns = 3;
  s.iterations = {2};
  s.cost_ns = {900, 800, 400, 0};
  t.step_info = {s};
  t.tasks[0].cpu_ns = 950;
  return t;
}

TEST(Timeline, KeepsGraphsStepInfoAndCpuTimeThroughGzip) {
  const Timeline t = with_graph();
  const std::string path = (test::scratch_dir("timeline_gzip") / "r.json").string();
  write_timeline(path, t);
  const std::string bytes = read_file_text(path);
  ASSERT_GE(bytes.size(), 2u);
  EXPECT_EQ(static_cast<unsigned char>(bytes[0]), 0x1f);  // gzip
  const Timeline back = read_timeline(path);
  ASSERT_EQ(back.tasks.size(), t.tasks.size());
  for (std::size_t i = 0; i < t.tasks.size(); ++i) {
    EXPECT_EQ(back.tasks[i].start_ns, t.tasks[i].start_ns) << i;
    EXPECT_EQ(back.tasks[i].end_ns, t.tasks[i].end_ns) << i;
    EXPECT_EQ(back.tasks[i].cpu_ns, t.tasks[i].cpu_ns) << i;
    EXPECT_EQ(back.tasks[i].kind, t.tasks[i].kind) << i;
  }
  ASSERT_EQ(back.graphs.size(), 1u);
  EXPECT_EQ(back.graphs[0], t.graphs[0]);
  ASSERT_EQ(back.step_info.size(), 1u);
  const TimelineStep& s = back.step_info[0];
  EXPECT_EQ(s.serial_ns(), 18);
  EXPECT_EQ(s.host_ns, 3);
  EXPECT_EQ(s.cost_ns, (std::vector<std::int64_t>{900, 800, 400, 0}));
  EXPECT_EQ(back.info(0), &back.step_info[0]);
  EXPECT_EQ(back.info(1), nullptr);
  // The format of one object per event carries the same.
  const Timeline objects = parse_timeline(timeline_json(t), "objects.json");
  EXPECT_EQ(objects.graphs, back.graphs);
  EXPECT_EQ(objects.step_info[0].cost_ns, s.cost_ns);
  EXPECT_EQ(objects.tasks[0].cpu_ns, 950);
  EXPECT_EQ(compact_timeline_json(objects), compact_timeline_json(back));
}

TEST(Timeline, RejectsGraphIndicesOutOfRange) {
  Timeline t = with_graph();
  t.graphs[0].edges.push_back({3, 1, 0, EdgeKind::RAW});  // backwards
  EXPECT_THROW(parse_timeline(timeline_json(t), "bad.json"), InputError);
  t = with_graph();
  t.tasks[0].task = 9;  // not a task of step 0's graph
  EXPECT_THROW(parse_timeline(timeline_json(t), "bad.json"), InputError);
  t = with_graph();
  t.step_info[0].cost_ns.pop_back();  // a cost per task
  EXPECT_THROW(parse_timeline(timeline_json(t), "bad.json"), InputError);
  EXPECT_THROW(parse_timeline(compact_timeline_json(t), "bad.json"), InputError);
  EXPECT_THROW(parse_timeline(std::string("\x1f\x8b garbage"), "bad.gz"), InputError);
}

}  // namespace
}  // namespace tgraph
