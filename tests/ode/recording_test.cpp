// SPDX-License-Identifier: MIT
// A step's calls as a graph: one task per part of a call between its posts and waits, the
// edges exactly the releases, posts and waits declared through ODE's interface, no more.
#include "recording.hpp"

#include <gtest/gtest.h>

#include <map>
#include <set>
#include <string>
#include <utility>

#include "runtime.hpp"

namespace tgraph::ode::detail {
namespace {

struct World {
  const dThreadingFunctionsInfo* f;
  dThreadingImplementationID impl;
  dCallReleaseeID r = nullptr;
};

int leaf(void*, dcallindex_t, dCallReleaseeID) { return 1; }

// A posts S as its own sub-call (S releases A, which already runs), then returns.
int call_a(void* w, dcallindex_t, dCallReleaseeID self) {
  auto* world = static_cast<World*>(w);
  world->f->alter_call_dependencies_count(world->impl, self, 1);
  world->f->post_call(world->impl, nullptr, nullptr, 0, self, nullptr, &leaf, nullptr, 0, "S");
  return 1;
}

// "kind#i": the i-th task of that kind in program order.
std::string label(const StepGraph& g, TaskId t) {
  int i = 0;
  for (TaskId u = 0; u < t; ++u) i += g.kind_name(u) == g.kind_name(t);
  return g.kind_name(t) + "#" + std::to_string(i);
}

// A recording runtime on GetParam() threads (no watchdog) and the interface ODE calls it by.
class Recording : public ::testing::TestWithParam<std::uint32_t> {
 protected:
  static RuntimeOptions options() {
    RuntimeOptions o;
    o.threads = GetParam();
    o.watchdog_s = 0;
    return o;
  }
  Recording() : rt(options()), w{rt.functions(), rt.id()} { rt.set_recording(true); }
  Runtime rt;
  World w;
};

TEST_P(Recording, EdgesAreTheDeclaredPostsReleasesAndWaitsAndNoMore) {
  rt.begin_step("dWorldQuickStep");
  dCallWaitID wait = w.f->alloc_call_wait(w.impl);
  w.f->post_call(w.impl, nullptr, &w.r, 2, nullptr, wait, &leaf, nullptr, 0, "R");
  w.f->post_call(w.impl, nullptr, nullptr, 0, w.r, nullptr, &call_a, &w, 0, "A");
  w.f->post_call(w.impl, nullptr, nullptr, 0, w.r, nullptr, &leaf, nullptr, 0, "B");
  w.f->wait_call(w.impl, nullptr, wait, nullptr, "test");
  StepLog log = rt.end_step();
  w.f->free_call_wait(w.impl, wait);
  const StepGraph g = build_step_graph(log);
  ASSERT_EQ(g.validate(), "");
  std::set<std::pair<std::string, std::string>> edges;
  for (const Edge& e : g.edges) {
    EXPECT_LT(e.from, e.to);  // program order is topological
    EXPECT_EQ(e.kind, EdgeKind::RAW);
    edges.insert({label(g, e.from), label(g, e.to)});
  }
  EXPECT_EQ(edges.size(), g.edges.size());  // one edge per relation
  const std::set<std::pair<std::string, std::string>> expected = {
      // The stepping thread's own code, split at its three posts and its wait.
      {"dWorldQuickStep#0", "dWorldQuickStep#1"},
      {"dWorldQuickStep#1", "dWorldQuickStep#2"},
      {"dWorldQuickStep#2", "dWorldQuickStep#3"},
      {"dWorldQuickStep#3", "dWorldQuickStep#4"},
      // Each post: the part before it precedes the posted call.
      {"dWorldQuickStep#0", "R#0"},
      {"dWorldQuickStep#1", "A#0"},
      {"dWorldQuickStep#2", "B#0"},
      // A split at its post of S; S does not wait for A's rest.
      {"A#0", "A#1"},
      {"A#0", "S#0"},
      // R's releasers: A's last part, B, and S (A's sub-call: A completes after it).
      {"A#1", "R#0"},
      {"B#0", "R#0"},
      {"S#0", "R#0"},
      // The wait: R signals it, the stepping thread's last part follows.
      {"R#0", "dWorldQuickStep#4"}};
  EXPECT_EQ(edges, expected);
  EXPECT_EQ(g.tasks.size(), 10u);
  std::set<StableKey> keys;
  for (const Task& t : g.tasks) keys.insert(t.key);
  EXPECT_EQ(keys.size(), g.tasks.size());  // stable keys name each part once
}

TEST_P(Recording, KeysRepeatFromOneStepToTheNext) {
  std::vector<StepGraph> steps;
  dCallWaitID wait = w.f->alloc_call_wait(w.impl);  // as ODE keeps its wait from step to step
  for (int s = 0; s < 2; ++s) {
    rt.begin_step("dWorldStep");
    w.f->reset_call_wait(w.impl, wait);
    dCallReleaseeID r = nullptr;
    w.f->post_call(w.impl, nullptr, &r, 3, nullptr, wait, &leaf, nullptr, 0, "join");
    for (int i = 0; i < 3; ++i)
      w.f->post_call(w.impl, nullptr, nullptr, 0, r, nullptr, &leaf, nullptr, 7, "leaf");
    w.f->wait_call(w.impl, nullptr, wait, nullptr, "test");
    steps.push_back(build_step_graph(rt.end_step()));
  }
  w.f->free_call_wait(w.impl, wait);
  std::multiset<StableKey> a, b;
  for (const Task& t : steps[0].tasks) a.insert(t.key);
  for (const Task& t : steps[1].tasks) b.insert(t.key);
  EXPECT_EQ(a, b);
  EXPECT_TRUE(steps[0].same_structure(steps[1]));
}

INSTANTIATE_TEST_SUITE_P(Threads, Recording, ::testing::Values(1u, 2u, 4u));

}  // namespace
}  // namespace tgraph::ode::detail
