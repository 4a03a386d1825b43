// SPDX-License-Identifier: MIT
// Collision detection as tasks of the step graph: the contacts it finds, step by step, are
// those of the sequential detection on the host (CollisionSettings::in_graph = false).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "test_util.hpp"
#include "tgraph/capture/recorder.hpp"
#include "tgraph/samples/scene.hpp"

namespace tgraph::samples {
namespace {

bool is_detection(const StepGraph& g, TaskId t) {
  const std::string& k = g.kinds[g.tasks[t].kind];
  return k == "updateProxy" || k == "collidePair" || k == "collideFloor";
}

// Runs a deferred step program with its detection tasks in another valid order than the
// program's: the other tasks in program order (loops repeated), then the proxies, then the
// narrow phases, each last-recorded first (a narrow phase reads only proxies and writes its
// own contact set, so whichever thread runs it first, the results must be the same).
void run_detection_reversed(capture::StepProgram& p) {
  std::vector<TaskId> proxies, narrow;
  for (TaskId t = 0; t < p.graph.tasks.size(); ++t) {
    if (!is_detection(p.graph, t)) continue;
    (p.graph.kinds[p.graph.tasks[t].kind] == "updateProxy" ? proxies : narrow).push_back(t);
  }
  std::vector<std::function<void()>> kept(p.bodies.size());
  for (TaskId t : proxies) std::swap(kept[t], p.bodies[t]);
  for (TaskId t : narrow) std::swap(kept[t], p.bodies[t]);
  test::run_program(p);
  for (auto it = proxies.rbegin(); it != proxies.rend(); ++it) kept[*it]();
  for (auto it = narrow.rbegin(); it != narrow.rend(); ++it) kept[*it]();
  for (TaskId t : proxies) std::swap(kept[t], p.bodies[t]);
  for (TaskId t : narrow) std::swap(kept[t], p.bodies[t]);
}

void expect_same_contacts(const Scene& want, const Scene& got, int step) {
  const auto wc = want.contact_fields(), gc = got.contact_fields();
  ASSERT_EQ(wc.size(), gc.size()) << "step " << step;
  for (std::size_t c = 0; c < wc.size(); ++c) {
    ASSERT_EQ(wc[c]->name(), gc[c]->name()) << "step " << step;
    const auto& wp = wc[c]->pairs();
    const auto& gp = gc[c]->pairs();
    ASSERT_EQ(wp.size(), gp.size()) << "step " << step << " " << wc[c]->name();
    for (std::size_t k = 0; k < wp.size(); ++k) {
      ASSERT_EQ(wp[k].i, gp[k].i) << "step " << step << " " << wc[c]->name() << " pair " << k;
      ASSERT_EQ(wp[k].j, gp[k].j) << "step " << step << " " << wc[c]->name() << " pair " << k;
    }
  }
  const auto wf = want.floor_fields(), gf = got.floor_fields();
  ASSERT_EQ(wf.size(), gf.size());
  for (std::size_t f = 0; f < wf.size(); ++f)
    ASSERT_EQ(wf[f]->points(), gf[f]->points()) << "step " << step << " " << wf[f]->name();
}

class CollisionInGraph : public ::testing::TestWithParam<const char*> {};

// Every step of the scene's default run: the deferred in-graph scene (its programs kept and
// run again while the structure repeats, detection tasks run out of program order) against
// the sequential reference, contact by contact, then the final positions bit for bit.
TEST_P(CollisionInGraph, FindsTheSequentialContactsOnEveryStep) {
  const std::string name = GetParam();
  if (!builtin_scene_text(name)) GTEST_SKIP() << name << " is not a built-in scene in this tree";
  auto reference = make_scene(name);
  auto in_graph = make_scene(name);
  reference->collision().in_graph = false;
  ASSERT_TRUE(in_graph->collision().enabled && in_graph->collision().in_graph);
  capture::Recorder plain(capture::Mode::kOff);
  capture::Recorder def(capture::Mode::kDeferred);
  capture::StepProgram program;
  std::uint64_t narrow_tasks = 0, host_narrow = 0, reused = 0, contact_steps = 0;
  for (int k = 0; k < reference->default_steps(); ++k) {
    reference->step(plain);
    plain.end_step();
    if (in_graph->step_if_changed(def))
      program = def.end_step_program();
    else
      ++reused;
    expect_same_contacts(*reference, *in_graph, k);
    if (HasFatalFailure()) return;
    if (!in_graph->contact_fields().empty()) ++contact_steps;
    const StepStats s = in_graph->last_stats();
    narrow_tasks += s.narrow_tasks;
    if (k > 0) host_narrow += s.host_narrow;
    EXPECT_EQ(reference->last_stats().narrow_tasks, 0u);
    run_detection_reversed(program);
  }
  EXPECT_EQ(def.errors(), 0u);
  EXPECT_GT(contact_steps, 0u) << "no contact to compare";
  EXPECT_GT(reused, 0u) << "no structure was reused";
  // The narrow phases ran in the graph: after the first step (whose contacts no earlier
  // task found) the host ran at most 1 % of them.
  RecordProperty("narrow_tasks", std::to_string(narrow_tasks));
  RecordProperty("host_narrow", std::to_string(host_narrow));
  RecordProperty("reused_steps", std::to_string(reused));
  EXPECT_GT(narrow_tasks, 0u);
  EXPECT_LE(host_narrow * 100, narrow_tasks) << host_narrow << " of " << narrow_tasks;
  for (std::size_t b = 0; b < reference->bodies().size(); ++b)
    EXPECT_EQ(reference->bodies()[b]->vec(VecId::kX), in_graph->bodies()[b]->vec(VecId::kX))
        << reference->bodies()[b]->name();
}

INSTANTIATE_TEST_SUITE_P(Scenes, CollisionInGraph, ::testing::Values("falling", "falling64"),
                         [](const ::testing::TestParamInfo<const char*>& i) { return std::string(i.param); });

// The detection tasks a step records: one proxy per body with a surface, reading its
// positions; a narrow phase per planned pair or floor contact reading proxies only.
TEST(CollisionInGraph, StepRecordsProxyAndNarrowPhaseTasks) {
  auto s = make_scene("falling");
  capture::Recorder rec(capture::Mode::kCapture);
  std::size_t with_surface = 0;
  for (const auto& b : s->bodies()) with_surface += b->surface.empty() ? 0 : 1;
  for (int k = 0; k < 2; ++k) {
    s->step(rec);
    const StepGraph g = rec.end_step();
    std::size_t proxies = 0, narrow = 0;
    bool seen_detection = false;
    for (TaskId t = 0; t < g.tasks.size(); ++t) {
      const std::string& kind = g.kinds[g.tasks[t].kind];
      if (!is_detection(g, t)) {
        EXPECT_FALSE(seen_detection) << "step " << k << ": " << kind << " after the detection tasks";
        continue;
      }
      seen_detection = true;
      for (const Access& a : g.accesses_of(t)) {
        const std::string& datum = g.data[a.datum].name;
        const bool reads = a.mode == AccessMode::R;
        if (kind == "updateProxy")
          EXPECT_TRUE(reads ? datum.ends_with(".x") : datum.ends_with(".proxy")) << datum;
        else
          EXPECT_TRUE(reads ? datum.ends_with(".proxy") : datum.ends_with(".set") || datum.ends_with(".points"))
              << kind << " " << datum;
      }
      (kind == "updateProxy" ? proxies : narrow) += 1;
    }
    EXPECT_EQ(proxies, with_surface);
    EXPECT_EQ(narrow, s->last_stats().narrow_tasks);
    EXPECT_GT(narrow, 0u);  // the objects in the tray are near its walls and floor
  }
}

}  // namespace
}  // namespace tgraph::samples
