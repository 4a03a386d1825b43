// SPDX-License-Identifier: MIT
// Generated steps (tgraph generate): shapes, determinism, sizes, bad options.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <vector>

#include "tgraph/graph/error.hpp"
#include "tgraph/graph/generate.hpp"
#include "tgraph/graph/metrics.hpp"
#include "tgraph/graph/trace_io.hpp"

namespace tgraph {
namespace {

std::vector<TaskId> raw_sources(const StepGraph& g, TaskId to) {
  std::vector<TaskId> out;
  for (const Edge& e : g.edges)
    if (e.to == to && e.kind == EdgeKind::RAW) out.push_back(e.from);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

TEST(Generate, StencilTaskReadsItsNeighboursInThePreviousLayer) {
  StepGraph g = generate_step({.tasks = 12, .pattern = Pattern::kStencil, .width = 4});
  g.derive_edges();
  ASSERT_EQ(g.tasks.size(), 12u);
  EXPECT_EQ(g.data.size(), 8u);  // two buffers of four cells
  // Task 5 is column 1 of layer 1: cells 0..2 of buffer 0, written by tasks 0..2.
  EXPECT_EQ(raw_sources(g, 5), (std::vector<TaskId>{0, 1, 2}));
  EXPECT_EQ(raw_sources(g, 4), (std::vector<TaskId>{0, 1}));   // left border
  EXPECT_EQ(raw_sources(g, 11), (std::vector<TaskId>{6, 7}));  // layer 2, right border
  EXPECT_TRUE(raw_sources(g, 3).empty());                      // layer 0 reads nothing
  // Buffer 0 again in layer 2: the writer of cell 1 waits for layer 1's readers of it.
  std::vector<TaskId> war;
  for (const Edge& e : g.edges)
    if (e.to == 9 && e.kind == EdgeKind::WAR) war.push_back(e.from);
  EXPECT_EQ(war, (std::vector<TaskId>{4, 5, 6}));
}

TEST(Generate, TreeTaskReadsItsButterflyPartner) {
  StepGraph g = generate_step({.tasks = 24, .pattern = Pattern::kTree, .width = 8});
  g.derive_edges();
  // Layer 1 pairs columns at distance 1, layer 2 at distance 2: task 8 + 2 * 8 + 5 = 21
  // is column 5 of layer 2, partner 5 xor 2 = 7 of layer 1 (tasks 13 and 15).
  EXPECT_EQ(raw_sources(g, 8 + 5), (std::vector<TaskId>{4, 5}));
  EXPECT_EQ(raw_sources(g, 16 + 5), (std::vector<TaskId>{13, 15}));
}

TEST(Generate, RandomReadsAtMostDegreePlusOneCellsAndDependsOnTheSeed) {
  const GenerateOptions o{.tasks = 4000, .pattern = Pattern::kRandom, .width = 400, .degree = 3};
  const StepGraph a = generate_step(o);
  for (TaskId t = 400; t < a.tasks.size(); ++t) {
    EXPECT_GE(a.accesses_of(t).size(), 2u);
    EXPECT_LE(a.accesses_of(t).size(), 5u);  // own cell, up to 3 others, the write
  }
  EXPECT_EQ(a, generate_step(o));
  GenerateOptions other = o;
  other.seed = 2;
  EXPECT_NE(a.accesses, generate_step(other).accesses);
}

TEST(Generate, EveryPatternGivesAValidStepOfTheRequestedSize) {
  for (const Pattern p : {Pattern::kTrivial, Pattern::kStencil, Pattern::kRandom, Pattern::kTree,
                          Pattern::kDomain}) {
    SCOPED_TRACE(std::string(to_string(p)));
    EXPECT_EQ(pattern_from_string(to_string(p)), p);
    StepGraph g = generate_step({.tasks = 5000, .pattern = p, .cost_ns = 2000});
    EXPECT_EQ(g.validate(), "");
    if (p == Pattern::kDomain) {
      EXPECT_NEAR(static_cast<double>(g.tasks.size()), 5000.0, 50.0);
      ASSERT_EQ(g.loops.size(), 1u);
    } else {
      EXPECT_EQ(g.tasks.size(), 5000u);
    }
    for (const Task& t : g.tasks) {
      EXPECT_GE(t.cost_ns, 1000u);
      EXPECT_LE(t.cost_ns, 3000u);
    }
    g.derive_edges();
    const Metrics m = compute_metrics(g);
    EXPECT_GT(m.parallelism, 1.0);
  }
  EXPECT_FALSE(pattern_from_string("grid").has_value());
}

TEST(Generate, StepsShareTheStructureAndDrawTheirOwnCosts) {
  const Trace t = generate_trace({.tasks = 300, .pattern = Pattern::kStencil}, 3);
  ASSERT_EQ(t.steps.size(), 3u);
  EXPECT_TRUE(t.steps[1].same_structure(t.steps[0]));
  EXPECT_EQ(t.steps[2].edges, t.steps[0].edges);
  EXPECT_FALSE(t.steps[2].edges.empty());
  EXPECT_NE(t.steps[1].tasks, t.steps[0].tasks);  // the costs differ
  EXPECT_EQ(t.header.scene, "generated-stencil");
}

TEST(Generate, FileHoldsTheTraceItsReportDescribes) {
  const std::string path =
      (std::filesystem::temp_directory_path() / "tgraph_generate_test.tgt").string();
  const GeneratedFile f = generate_file({.tasks = 12, .width = 4, .seed = 9}, 2, path);
  const Trace t = read_trace(path);
  std::filesystem::remove(path);
  ASSERT_EQ(t.steps.size(), 2u);
  EXPECT_EQ(t, generate_trace({.tasks = 12, .width = 4, .seed = 9}, 2));
  EXPECT_EQ(f.tasks, 12u);
  EXPECT_EQ(f.data, 8u);
  EXPECT_EQ(f.edges, t.steps[0].edges.size());
  const nlohmann::json j = nlohmann::json::parse(generated_json(f));
  EXPECT_EQ(j["trace"], path);
  EXPECT_EQ(j["pattern"], "stencil");
  EXPECT_EQ(j["steps"], 2);
  EXPECT_EQ(j["tasks"], 12);
  EXPECT_EQ(j["accesses"], f.accesses);
  EXPECT_EQ(j["seed"], 9);
  EXPECT_EQ(generated_text(f).rfind("wrote " + path + ": 2 step(s) of 12 tasks, 8 data, ", 0), 0u);
}

TEST(Generate, RejectsNoTasksAndAWidthAboveTheTasks) {
  try {
    generate_step({.tasks = 10, .width = 11});
    ADD_FAILURE() << "a width above the tasks";
  } catch (const OptionError& e) {
    EXPECT_STREQ(e.what(), "width: expected at most tasks (10)");
  }
  EXPECT_THROW(generate_step({.tasks = 0}), UsageError);
  EXPECT_THROW(generate_step({.tasks = 10, .width = 11}), UsageError);
  EXPECT_THROW(generate_step({.tasks = 10, .pattern = Pattern::kDomain, .iterations = 0}),
               UsageError);
}

}  // namespace
}  // namespace tgraph
