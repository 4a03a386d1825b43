// SPDX-License-Identifier: MIT
// `tgraph export --format json`: every part of the step, with derived edges.
#include "tgraph/graph/step_json.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace tgraph {
namespace {

TEST(StepJson, CarriesTasksAccessesDataLoopsEdgesAndContacts) {
  StepGraph g;
  g.kinds = {"op", "loop.break"};
  g.objects = {{"a"}, {"b"}};
  g.data = {{"x", 0, 64}, {"cond", kNoObject, 1}};
  const Access w[] = {{0, AccessMode::W}}, body[] = {{0, AccessMode::RW}, {1, AccessMode::W}},
               brk[] = {{1, AccessMode::R}};
  g.add_task(0, 0, w, 7, 11);
  g.add_task(0, 1, body, 3, 12);
  g.add_task(1, kNoObject, brk, 1, 13);
  g.tasks[1].loop = g.tasks[2].loop = 0;
  g.loops.push_back({1, 1, 3, 4, 50});
  g.contacts = {{0, 1}};
  g.groups = {0, 0};
  g.derive_edges();
  const nlohmann::json j = nlohmann::json::parse(step_graph_json(g, 9));
  EXPECT_EQ(j["step"], 9);
  EXPECT_EQ(j["objects"], nlohmann::json::array({"a", "b"}));
  EXPECT_EQ(j["data"][0], nlohmann::json({{"name", "x"}, {"object", 0}, {"bytes", 64}}));
  EXPECT_TRUE(j["data"][1]["object"].is_null());
  ASSERT_EQ(j["tasks"].size(), 3u);
  EXPECT_EQ(j["tasks"][1]["kind"], "op");
  EXPECT_EQ(j["tasks"][1]["cost_ns"], 3);
  EXPECT_EQ(j["tasks"][1]["loop"], 0);
  EXPECT_TRUE(j["tasks"][0]["loop"].is_null());
  EXPECT_TRUE(j["tasks"][2]["object"].is_null());
  EXPECT_EQ(j["tasks"][2]["key"], 13);
  EXPECT_EQ(j["tasks"][1]["accesses"][0], nlohmann::json({{"datum", 0}, {"mode", "RW"}}));
  EXPECT_EQ(j["loops"][0]["iterations"], 4);
  EXPECT_EQ(j["loops"][0]["max_iterations"], 50);
  EXPECT_EQ(j["edges"].size(), g.edges.size());
  EXPECT_EQ(j["carried_edges"].size(), g.carried_edges.size());
  EXPECT_EQ(j["edges"][0]["bytes"], g.data[g.edges[0].datum].bytes);
  EXPECT_EQ(j["contacts"], nlohmann::json::parse("[[0, 1]]"));
  EXPECT_EQ(j["groups"], nlohmann::json::array({0, 0}));
}

}  // namespace
}  // namespace tgraph
