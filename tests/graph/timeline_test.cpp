// SPDX-License-Identifier: MIT
// The timeline model: its JSON writer and reader, step offsets.
#include "tgraph/graph/timeline.hpp"

#include <gtest/gtest.h>

#include <optional>
#include <tuple>
#include <vector>

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

}  // namespace
}  // namespace tgraph
