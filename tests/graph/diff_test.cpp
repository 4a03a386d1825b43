// SPDX-License-Identifier: MIT
// diff_steps: tasks and edges by stable key, contacts and groups by object name.
#include "tgraph/graph/diff.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace tgraph {
namespace {

using M = AccessMode;

// Bodies (declared in the order given), one update task each (key 10 + body index in
// `names`), then per contact (i, j) a force task on an interaction object writing both bodies'
// forces (key 1000 + 10 i + j). `group[i]` is body i's collision group.
StepGraph scene(const std::vector<std::string>& names, const std::vector<std::string>& order,
                const std::vector<std::pair<int, int>>& contacts,
                const std::vector<std::uint32_t>& group) {
  StepGraph g;
  g.kinds = {"update", "force"};
  std::vector<ObjectId> id(names.size());
  std::vector<DatumId> f(names.size());
  for (const std::string& n : order) {
    const auto i =
        static_cast<std::size_t>(std::find(names.begin(), names.end(), n) - names.begin());
    id[i] = static_cast<ObjectId>(g.objects.size());
    g.objects.push_back({n});
    g.groups.push_back(group[i]);
  }
  for (std::size_t i = 0; i < names.size(); ++i) {
    f[i] = static_cast<DatumId>(g.data.size());
    g.data.push_back({names[i] + ".f", id[i], 64});
  }
  for (std::size_t i = 0; i < names.size(); ++i) {
    const Access a[] = {{f[i], M::RW}};
    g.add_task(0, id[i], a, 10, 10 + i);
  }
  for (const auto& [i, j] : contacts) {
    const auto ui = static_cast<std::size_t>(i), uj = static_cast<std::size_t>(j);
    const ObjectId o = static_cast<ObjectId>(g.objects.size());
    g.objects.push_back({"contact[" + names[ui] + "|" + names[uj] + "]"});
    const Access a[] = {{f[ui], M::CW}, {f[uj], M::CW}};
    g.add_task(1, o, a, 5, static_cast<StableKey>(1000 + 10 * i + j));
    g.contacts.push_back({std::min(id[ui], id[uj]), std::max(id[ui], id[uj])});
  }
  std::sort(g.contacts.begin(), g.contacts.end());
  for (std::size_t i = 0; i < names.size(); ++i) {
    const Access a[] = {{f[i], M::R}};
    g.add_task(0, id[i], a, 10, 20 + i);
  }
  g.derive_edges();
  return g;
}

const std::vector<std::string> kNames = {"ball", "box", "cube"};

TEST(Diff, FindsNothingBetweenEqualSteps) {
  const StepGraph a = scene(kNames, kNames, {{0, 1}}, {0, 0, 1});
  const StepDiff d = diff_steps(a, a);
  EXPECT_TRUE(d.same_structure);
  EXPECT_EQ(d.matched_tasks, a.tasks.size());
  EXPECT_TRUE(d.tasks_added.empty() && d.tasks_removed.empty() && d.edges_added.empty() &&
              d.edges_removed.empty());
  EXPECT_TRUE(d.groups_merged.empty() && d.groups_split.empty());
  EXPECT_EQ(step_diff_summary(d), "no structural change");
}

TEST(Diff, NamesTheContactThatMergedTwoGroupsEvenWhenObjectIdsMove) {
  const StepGraph before = scene(kNames, kNames, {}, {0, 1, 2});
  // The same bodies declared in another order: ids differ, names do not.
  const StepGraph after = scene(kNames, {"cube", "ball", "box"}, {{0, 1}}, {0, 0, 1});
  const StepDiff d = diff_steps(before, after);
  EXPECT_FALSE(d.same_structure);
  EXPECT_EQ(d.matched_tasks, before.tasks.size());
  ASSERT_EQ(d.tasks_added.size(), 1u);
  EXPECT_EQ(d.tasks_added[0].key, 1001u);
  EXPECT_EQ(d.tasks_added[0].kind, "force");
  EXPECT_EQ(d.tasks_added[0].object, "contact[ball|box]");
  EXPECT_EQ(d.tasks_added[0].caused_by, (std::vector<std::string>{"ball|box"}));
  EXPECT_TRUE(d.tasks_removed.empty());
  EXPECT_EQ(d.contacts_added, (std::vector<std::string>{"ball|box"}));
  EXPECT_TRUE(d.contacts_removed.empty());
  // The new task writes ball.f and box.f between each body's two tasks: 4 new edges, and the
  // two direct update -> read edges it now sits between are gone.
  for (const EdgeRef& e : d.edges_added) EXPECT_TRUE(e.from == 1001 || e.to == 1001) << e.datum;
  EXPECT_EQ(d.edges_added.size(), 4u);
  EXPECT_EQ(d.edges_removed.size(), 2u);
  ASSERT_EQ(d.groups_merged.size(), 1u);
  // Members in the order of the later step's objects: cube, ball, box.
  EXPECT_EQ(d.groups_merged[0].from, (std::vector<std::vector<std::string>>{{"ball"}, {"box"}}));
  EXPECT_EQ(d.groups_merged[0].into, (std::vector<std::vector<std::string>>{{"ball", "box"}}));
  EXPECT_EQ(d.groups_merged[0].contacts, (std::vector<std::string>{"ball|box"}));
  EXPECT_TRUE(d.groups_split.empty());
  EXPECT_EQ(step_diff_summary(d),
            "+1/-0 tasks, +4/-2 edges, contacts +ball|box, groups merged: {ball} + {box}");
}

TEST(Diff, NamesTheLostContactOfASplit) {
  const StepGraph before = scene(kNames, kNames, {{0, 1}, {1, 2}}, {0, 0, 0});
  const StepGraph after = scene(kNames, kNames, {{0, 1}}, {0, 0, 1});
  const StepDiff d = diff_steps(before, after);
  ASSERT_EQ(d.tasks_removed.size(), 1u);
  EXPECT_EQ(d.tasks_removed[0].key, 1012u);
  EXPECT_EQ(d.tasks_removed[0].caused_by, (std::vector<std::string>{"box|cube"}));
  EXPECT_EQ(d.contacts_removed, (std::vector<std::string>{"box|cube"}));
  ASSERT_EQ(d.groups_split.size(), 1u);
  // Interaction objects without a group entry are left out of the groups.
  EXPECT_EQ(d.groups_split[0].from,
            (std::vector<std::vector<std::string>>{{"ball", "box", "cube"}}));
  EXPECT_EQ(d.groups_split[0].into.size(), 2u);
  EXPECT_EQ(d.groups_split[0].contacts, (std::vector<std::string>{"box|cube"}));
  EXPECT_TRUE(d.groups_merged.empty());
}

TEST(Diff, ListsTasksWhoseProcessorChangedAndWritesJson) {
  const StepGraph before = scene(kNames, kNames, {}, {0, 1, 2});
  const StepGraph after = scene(kNames, kNames, {{1, 2}}, {0, 1, 1});
  StepDiff d = diff_steps(before, after);
  const Assignment pa{2, {0, 1, 1, 0, 1, 1}, {}};
  const Assignment pb{2, {0, 1, 0, 1, 1, 1, 1}, {}};  // cube's update and ball's read moved
  add_processor_changes(d, before, pa, after, pb);
  ASSERT_EQ(d.processor_changes.size(), 2u);
  EXPECT_EQ(d.processor_changes[0].task.key, 12u);
  EXPECT_EQ(d.processor_changes[0].from, 1u);
  EXPECT_EQ(d.processor_changes[0].to, 0u);
  EXPECT_EQ(d.processor_changes[1].task.key, 20u);
  const nlohmann::json j = nlohmann::json::parse(step_diff_json(d, 3, 4));
  EXPECT_EQ(j["steps"], nlohmann::json::array({3, 4}));
  EXPECT_EQ(j["contacts_added"], nlohmann::json::array({"box|cube"}));
  EXPECT_EQ(j["tasks_added"][0]["caused_by"], nlohmann::json::array({"box|cube"}));
  EXPECT_EQ(j["groups_merged"][0]["contacts"], nlohmann::json::array({"box|cube"}));
  EXPECT_EQ(j["processor_changes"].size(), 2u);
  EXPECT_EQ(j["processor_changes"][0]["to"], 0);
  EXPECT_EQ(j["summary"], step_diff_summary(d));
  const std::string text = step_diff_text(d, 3, 4);
  EXPECT_NE(text.find("  + task force on contact[box|cube] (key 1012), contact box|cube\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("  groups merged: {box} + {cube} -> {box, cube} by contact box|cube\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("processor 1 -> 0"), std::string::npos);
}

TEST(Diff, MatchesRepeatedKeysByOccurrence) {
  StepGraph a, b;
  for (StepGraph* g : {&a, &b}) {
    g->kinds = {"op"};
    g->data = {{"x", kNoObject, 8}};
  }
  const Access w[] = {{0, M::RW}};
  for (int i = 0; i < 3; ++i) a.add_task(0, kNoObject, w, 1, 7);
  for (int i = 0; i < 2; ++i) b.add_task(0, kNoObject, w, 1, 7);
  a.derive_edges();
  b.derive_edges();
  EXPECT_EQ(match_tasks_by_key(b, a), (std::vector<TaskId>{0, 1}));
  const StepDiff d = diff_steps(a, b);
  ASSERT_EQ(d.tasks_removed.size(), 1u);
  EXPECT_EQ(d.tasks_removed[0].id, 2u);
  EXPECT_EQ(d.edges_removed.size(), 1u);  // the third task's dependency on the second
}

}  // namespace
}  // namespace tgraph
