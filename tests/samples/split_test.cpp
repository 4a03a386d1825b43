// SPDX-License-Identifier: MIT
// split=N: a deformable object's internal force field as N tasks over element or spring
// ranges. The physics is the same bit for bit, the N tasks are independent in the step
// graph, and a partitioner can spread them.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <string>

#include "test_util.hpp"
#include "tgraph/graph/error.hpp"
#include "tgraph/partition/strategy.hpp"

namespace tgraph::samples {
namespace {

// A FEM bar, a spring grid and a chain falling onto a floor and onto each other.
std::unique_ptr<Scene> objects(const std::string& split, std::optional<int> cli = std::nullopt) {
  SceneOptions o;
  o.split = cli;
  return parse_scene(
      test::scene_text(
          "scene name=split\nsolver integrator=implicit dt=0.005 tolerance=1e-6 max_iterations=300\n"
          "gravity value=0,-9.81,0\ncollision stiffness=2e4 alarm=0.02 floor=0\n"
          "fem name=bar nodes=16,4,4 size=0.5,0.12,0.12 center=0,0.1,0 young=5e5 density=500 " +
          split +
          "\nspringgrid name=grid nodes=8,5,8 size=0.34,0.2,0.34 center=0,0.3,0 stiffness=3e3 density=500 " +
          split +
          "\nchain name=rope nodes=120 rows=6 segment=0.02 row_gap=0.03 center=0,0.45,0 stiffness=2e3 bend=100 "
          "mass=2 " +
          split + "\n"),
      "split.scene", o);
}

std::vector<double> positions(const Scene& s) {
  std::vector<double> out;
  for (const auto& b : s.bodies()) {
    const StateVec& x = b->vec(VecId::kX);
    out.insert(out.end(), x.data(), x.data() + x.size());
  }
  return out;
}

TEST(Split, ForceFieldsOverElementAndSpringRangesGiveTheSamePhysicsBitForBit) {
  auto whole = objects("");
  auto cut = objects("split=4");
  // bar: 5 element batches in runs of 2 (3 fields); grid: 4 spring ranges; rope: 4.
  EXPECT_EQ(whole->force_fields().size() + 2 + 3 + 3, cut->force_fields().size());
  test::run(*whole, 40);
  test::run(*cut, 40);
  EXPECT_GT(whole->last_stats().contact_fields, 0u);  // the objects touch
  EXPECT_EQ(positions(*whole), positions(*cut));
  EXPECT_EQ(whole->last_stats().cg_iterations, cut->last_stats().cg_iterations);
}

TEST(Split, CommandLineOverrideSplitsEveryDeformableObject) {
  auto file = objects("split=3");
  auto cli = objects("", 3);
  EXPECT_EQ(file->force_fields().size(), cli->force_fields().size());
  auto over = objects("split=3", 1);  // the override wins over the file
  EXPECT_EQ(over->force_fields().size(), objects("")->force_fields().size());
}

TEST(Split, SplitMustBeAPositiveCount) {
  EXPECT_THROW(objects("split=0"), InputError);
  SceneOptions o;
  o.split = 0;
  EXPECT_THROW(parse_scene(test::scene_text("scene name=s\nchain name=c nodes=10 segment=0.1 stiffness=10 mass=1\n"),
                           "s", o),
               UsageError);
}

// The addDForce tasks of the bar in the first CG iteration of a captured step.
std::vector<TaskId> bar_dforce_tasks(const StepGraph& g) {
  const auto kind = std::find(g.kinds.begin(), g.kinds.end(), "addDForce") - g.kinds.begin();
  ObjectId bar = kNoObject;
  for (ObjectId o = 0; o < g.objects.size(); ++o)
    if (g.objects[o].name == "bar") bar = o;
  std::vector<TaskId> out;
  for (TaskId t = 0; t < g.tasks.size(); ++t)
    if (g.tasks[t].kind == static_cast<KindId>(kind) && g.tasks[t].object == bar) out.push_back(t);
  return out;
}

TEST(Split, TheSplitObjectsTasksAreIndependentAndAPartitionerSpreadsThem) {
  auto s = objects("split=4");
  capture::Recorder rec(capture::Mode::kCapture);
  StepGraph g;
  for (int k = 0; k < 3; ++k) {
    s->step(rec);
    g = rec.end_step();
  }
  // 135 elements in 5 batches of up to 32: runs of 2 batches, 3 fields, plus the floor
  // contact; the addDForce tasks before the loop (f += K v) and in its body (q += K p).
  const std::vector<TaskId> tasks = bar_dforce_tasks(g);
  ASSERT_EQ(tasks.size(), 8u);
  // No edge joins two of them (cumulative writes of one vector commute), directly or not.
  std::vector<std::set<TaskId>> reach(g.tasks.size());
  for (TaskId t = static_cast<TaskId>(g.tasks.size()); t-- > 0;) {
    for (const Edge& e : g.edges)
      if (e.from == t) {
        reach[t].insert(e.to);
        reach[t].insert(reach[e.to].begin(), reach[e.to].end());
      }
  }
  for (std::size_t i = 0; i < 4; ++i)
    for (std::size_t j = 0; j < 4; ++j) {
      EXPECT_EQ(reach[tasks[i]].count(tasks[j]), 0u) << i << " " << j;
      EXPECT_EQ(reach[tasks[4 + i]].count(tasks[4 + j]), 0u) << i << " " << j;
    }
  // When the bar's batches dominate the step (as a large FEM object's do, the torso's
  // liver), a graph partitioner puts them on more than one processor. The costs are set, not
  // measured: measured ones vary from build to build (a sanitizer slows some kinds more than
  // others) and this bar is small; the test is about the graph's shape allowing the spread.
  for (Task& t : g.tasks) t.cost_ns = 1000;
  for (TaskId t : tasks) g.tasks[t].cost_ns = 50000;
  const partition::Result r = partition::make_strategy("metis")->partition(g, 3, {}, {});
  std::set<ProcId> procs;
  for (TaskId t : tasks) procs.insert(r.assignment.proc[t]);
  EXPECT_GT(procs.size(), 1u);
}

}  // namespace
}  // namespace tgraph::samples
