// SPDX-License-Identifier: MIT
// Live mode: the engine's own task bodies run by every executor give the same state as a
// sequential run, bit for bit.
#include <gtest/gtest.h>

#if defined(TGRAPH_HAVE_SAMPLES) && defined(TGRAPH_HAVE_PARTITION) && defined(TGRAPH_HAVE_CAPTURE)

#include <memory>
#include <string>

#include "tgraph/capture/recorder.hpp"
#include "tgraph/partition/strategy.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/live.hpp"
#include "tgraph/samples/scene.hpp"

namespace tgraph::replay {
namespace {

StateSnapshot run_live(const std::string& scene_name, Policy policy, std::uint32_t k, int steps,
                       std::uint32_t* loop_iterations = nullptr) {
  auto scene = samples::make_scene(scene_name);
  capture::Recorder rec(capture::Mode::kDeferred);
  ExecOptions eo;
  eo.threads = k;
  eo.cw = CwMode::kSerialize;
  eo.spin_ns = 20'000;
  auto ex = make_executor(policy, eo);
  auto owner = partition::make_strategy("owner");
  StepGraph last;
  for (int s = 0; s < steps; ++s) {
    scene->step(rec);
    capture::StepProgram prog = rec.end_step_program();
    EXPECT_EQ(rec.errors(), 0u);
    for (Task& t : prog.graph.tasks) t.cost_ns = 1;  // deferred recording has no costs
    Assignment a;
    if (policy == Policy::kPartition) a = owner->partition(prog.graph, k, {}, {}).assignment;
    ProgramWorkload w(prog.bodies, prog.conditions);
    const StepStats st = ex->run_step(prog.graph, policy == Policy::kPartition ? &a : nullptr, w);
    if (loop_iterations && !st.loop_iterations.empty()) *loop_iterations += st.loop_iterations[0];
    last = std::move(prog.graph);
  }
  std::vector<StateRegion> regions;
  for (DatumId d = 0; d < last.data.size(); ++d)
    if (rec.datum_ptr(d))
      regions.push_back({last.data[d].name, rec.datum_ptr(d), last.data[d].bytes});
  return snapshot(regions);
}

class LiveMode : public ::testing::TestWithParam<std::tuple<std::string, int>> {};

TEST_P(LiveMode, EveryPolicyAndThreadCountMatchesSequentialBitForBit) {
  const auto& [scene, steps] = GetParam();
  std::uint32_t iterations = 0;
  const StateSnapshot reference = run_live(scene, Policy::kSequential, 1, steps, &iterations);
  ASSERT_FALSE(reference.names.empty());
  if (scene != "falling") {
    EXPECT_GT(iterations, 0u) << "the implicit solver ran no CG iteration";
  }
  for (Policy p : {Policy::kPartition, Policy::kWorksteal, Policy::kBarrier}) {
    for (std::uint32_t k = 1; k <= 4; ++k) {
      const auto diff = compare(reference, run_live(scene, p, k, steps));
      EXPECT_FALSE(diff.has_value()) << scene << " " << to_string(p) << " k=" << k << ": datum "
                                     << (diff ? diff->datum : "") << " differs";
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, LiveMode,
                         ::testing::Values(std::make_tuple(std::string("bars64"), 1),
                                           std::make_tuple(std::string("falling"), 2),
                                           std::make_tuple(std::string("cloth128"), 1)),
                         [](const auto& param_info) { return std::get<0>(param_info.param); });

TEST(LiveCompare, NamesTheFirstDifferingDatum) {
  std::uint64_t a[4] = {1, 2, 3, 4}, b[4] = {1, 2, 3, 4}, c[2] = {7, 8}, d[2] = {7, 9};
  const StateRegion r1[] = {{"x", a, sizeof a}, {"v", c, sizeof c}};
  const StateRegion r2[] = {{"x", b, sizeof b}, {"v", d, sizeof d}};
  EXPECT_FALSE(compare(snapshot(r1), snapshot(r1)).has_value());
  const auto diff = compare(snapshot(r1), snapshot(r2));
  ASSERT_TRUE(diff.has_value());
  EXPECT_EQ(diff->datum, "v");
  EXPECT_EQ(diff->offset, 8u);
  EXPECT_EQ(diff->differing_bytes, 1u);
}

}  // namespace
}  // namespace tgraph::replay

#endif
