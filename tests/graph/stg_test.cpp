// SPDX-License-Identifier: MIT
// Standard Task Graph Set import: critical paths, dummy tasks, round trip, malformed files.
#include "../option_error.hpp"
#include "../stg_files.hpp"
#include "tgraph/graph/stg.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/metrics.hpp"
#include "tgraph/graph/trace_io.hpp"

namespace tgraph {
namespace {

using test::stg_files;

TEST(Stg, ReproducesTheStatedCriticalPathOfEveryGraph) {
  const std::vector<std::string> files = stg_files();
  ASSERT_EQ(files.size(), 20u) << "STG graphs expected under " << TGRAPH_TEST_DATA << "/stg";
  for (const std::string& f : files) {
    for (std::uint64_t unit : {1u, 1000u}) {
      const StgGraph s = read_stg(f, unit);
      ASSERT_TRUE(s.cp_length.has_value()) << f;
      ASSERT_EQ(s.trace.steps.size(), 1u);
      const Metrics m = compute_metrics(s.trace.steps[0]);
      EXPECT_EQ(m.span_ns, *s.cp_length * unit) << f;
    }
  }
}

TEST(Stg, KeepsDummyTasksAndEveryEdge) {
  const std::string f = std::string(TGRAPH_TEST_DATA) + "/stg/50/rand0000.stg";
  const StgGraph s = read_stg(f);
  const StepGraph& g = s.trace.steps[0];
  EXPECT_EQ(g.tasks.size(), 52u);
  EXPECT_EQ(g.tasks.front().cost_ns, 0u);
  EXPECT_EQ(g.tasks.back().cost_ns, 0u);
  EXPECT_EQ(g.tasks[1].cost_ns, 9000u);
  EXPECT_EQ(g.edges.size(), 96u + 23u) << "96 edges plus 23 from the entry / to the exit dummy";
  EXPECT_EQ(*s.cp_length, 55u);
}

TEST(Stg, SurvivesATraceFileRoundTrip) {
  const StgGraph s = read_stg(std::string(TGRAPH_TEST_DATA) + "/stg/100/rand0003.stg");
  const std::string path =
      (std::filesystem::temp_directory_path() / "tgraph_stg_test.tgt").string();
  write_trace(path, s.trace);
  const Trace back = read_trace(path);
  std::filesystem::remove(path);
  ASSERT_EQ(back.steps.size(), 1u);
  EXPECT_EQ(compute_metrics(back.steps[0]).span_ns, *s.cp_length * 1000);
  EXPECT_EQ(back.steps[0].edges, s.trace.steps[0].edges);
}

TEST(Stg, RejectsMalformedFilesWithTheOffset) {
  auto message = [](const std::string& text) {
    return test::input_error([&] { parse_stg(text, "g.stg"); });
  };
  EXPECT_NE(message("").find("g.stg: offset 0: truncated: expected the task count"),
            std::string::npos);
  EXPECT_NE(message("1\n0 0 0\n1 5 1 0\n").find("truncated: expected a task number"),
            std::string::npos);
  EXPECT_NE(message("1\n0 0 0\n2 5 1 0\n2 0 1 1\n").find("expected task number 1, got 2"),
            std::string::npos);
  EXPECT_NE(message("1\n0 0 0\n1 5 1 1\n2 0 1 1\n").find("predecessor numbered below 1"),
            std::string::npos);
  EXPECT_NE(message("1\n0 0 0\n1 x 1 0\n").find("offset 10: expected a processing time"),
            std::string::npos);
  EXPECT_NE(message("1\n0 0 0\n1 5 1 0\n2 0 1 1\n7\n").find("'#' trailer"), std::string::npos);
  EXPECT_EQ(message("1\n0 0 0\n1 5 1 0\n2 0 1 1\n# CP Length : 5\n"), "accepted");
}

}  // namespace
}  // namespace tgraph
