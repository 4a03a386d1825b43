// SPDX-License-Identifier: MIT
// Partition-guided stealing on the torso scene's own task bodies: at K = 8 with a mapping
// that leaves four threads nothing, those threads run ready tasks of the loaded
// processors, and the state after the steps is bit for bit that of the serial partition
// executor with the same assignments (the same per-processor reducers, in the same order).
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "tgraph/measure/engine.hpp"
#include "tgraph/measure/state.hpp"
#include "tgraph/partition/strategy.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/program_workload.hpp"

namespace tgraph::measure {
namespace {

using namespace tgraph::replay;

TEST(Steal, OnTorsoAtEightThreadsIdleThreadsTakeReadyTasksAndTheStateIsTheSerialRunsBitForBit) {
  // At least two steps; more (up to 20) until an idle thread has run a task: on a loaded
  // 2-core machine the OS may not run threads 4-7 at all while a short step lasts.
  constexpr std::uint32_t k = 8, mapped = 4, min_steps = 2, max_steps = 20;
  std::unique_ptr<LiveEngine> live = make_live_engine("torso");
  std::unique_ptr<LiveEngine> reference = make_live_engine("torso");
  ExecOptions o;
  o.threads = k;
  o.spin_ns = 2'000'000'000;  // idle threads look for tasks for as long as a step lasts
  auto ex = make_executor(Policy::kPartition, o);
  ExecOptions so = o;
  so.partition.serial = true;
  auto serial = make_executor(Policy::kPartition, so);
  const std::shared_ptr<partition::Strategy> strategy = partition::make_strategy("sticky");
  ProgramWorkload w, rw;
  std::uint64_t by_idle = 0, stolen = 0;
  for (std::uint32_t s = 0; s < max_steps && (s < min_steps || by_idle == 0); ++s) {
    LiveStep step = live->record_step(false);
    LiveStep ref = reference->record_step(false);
    ASSERT_EQ(step.graph.tasks.size(), ref.graph.tasks.size());
    for (Task& t : step.graph.tasks) t.cost_ns = 1;
    // The engine's tasks on processors 0-3 of 8: threads 4-7 have nothing mapped.
    Assignment a = strategy->partition(step.graph, mapped, {}, {}).assignment;
    a.k = k;
    w.set_program(step.bodies, step.conditions, step.accumulators);
    const ExecStepStats st = ex->run_step(step.graph, &a, w);
    rw.set_program(ref.bodies, ref.conditions, ref.accumulators);
    serial->run_step(ref.graph, &a, rw);
    ASSERT_EQ(st.threads.size(), k);
    for (std::uint32_t p = 0; p < k; ++p) {
      stolen += st.threads[p].stolen;
      if (p >= mapped) {
        EXPECT_EQ(st.threads[p].stolen, st.threads[p].tasks) << "thread " << p;
        by_idle += st.threads[p].tasks;
      }
    }
  }
  EXPECT_GT(by_idle, 0u);  // the idle threads ran tasks of processors 0-3
  EXPECT_GE(stolen, by_idle);
  const auto difference = compare(snapshot(reference->state()), snapshot(live->state()));
  EXPECT_FALSE(difference.has_value()) << "first difference in " << difference->datum;
}

}  // namespace
}  // namespace tgraph::measure
