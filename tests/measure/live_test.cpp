// SPDX-License-Identifier: MIT
// Live runs (measure::run_live): the engine's own task bodies through every executor, with
// parallel reductions, give the state of a sequential run that uses the same reduction
// order, bit for bit, over steps where contacts change and plans are rebuilt.
#include "tgraph/measure/live.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "tgraph/graph/error.hpp"
#include "tgraph/partition/strategy.hpp"
#include "tgraph/replay/program_workload.hpp"

namespace tgraph::measure {
namespace {

using namespace tgraph::replay;

#if defined(__SANITIZE_THREAD__)
// ThreadSanitizer runs ~10x slower; the first contact change of falling is at step 43.
constexpr std::uint32_t kFallingSteps = 50;
#else
constexpr std::uint32_t kFallingSteps = 150;
#endif

partition::StepPartitioner partitioner_for(const std::string& method) {
  std::shared_ptr<partition::Strategy> s = partition::make_strategy(method);
  return [s](const StepGraph& g, std::uint32_t k, const StepGraph* pg, const Assignment* pa) {
    return s->partition(g, k, partition::Previous{pg, pa}, {}).assignment;
  };
}

// A run of `steps` steps on k threads without the timed uninstrumented engine and without
// the observed passes (what the tests below look at is in the timed pass).
LiveOptions quiet_options(std::uint32_t k, std::uint32_t steps) {
  LiveOptions o;
  o.exec.threads = k;
  o.exec.spin_ns = 20'000;
  o.steps = steps;
  o.baseline = false;
  o.observe = false;
  return o;
}

LiveResult live(const std::string& scene, Policy policy, const std::string& method, std::uint32_t k,
                std::uint32_t steps, CwMode cw = CwMode::kReduce) {
  LiveOptions o = quiet_options(k, steps);
  o.policy = policy;
  o.exec.cw = cw;
  o.check = true;
  const partition::StepPartitioner p =
      policy == Policy::kPartition ? partitioner_for(method) : nullptr;
  return run_live([scene] { return make_live_engine(scene); },
                  policy == Policy::kPartition ? &p : nullptr, o);
}

struct FallingCase {
  Policy policy;
  const char* method;
  std::uint32_t threads;
};

class FallingLive : public ::testing::TestWithParam<FallingCase> {};

TEST_P(FallingLive, MatchesTheSameReductionOrderBitForBitThroughContactChanges) {
  const FallingCase c = GetParam();
  const LiveResult r = live("falling", c.policy, c.method, c.threads, kFallingSteps);
  EXPECT_EQ(r.cw, CwMode::kReduce);
  EXPECT_EQ(r.check, Check::kIdentical) << (r.difference ? r.difference->datum : "");
  EXPECT_GT(r.data_compared, 100u);
  // Contacts changed: the engine recorded new structures and the executor built new plans.
  std::uint32_t recorded = 0;
  for (const auto& s : r.steps) recorded += s.recorded ? 1 : 0;
  EXPECT_GE(recorded, 2u);
  EXPECT_GE(r.plans_built, 2u);
}

INSTANTIATE_TEST_SUITE_P(
    Policies, FallingLive,
    ::testing::Values(FallingCase{Policy::kPartition, "owner", 2},
                      FallingCase{Policy::kPartition, "owner", 3},
                      FallingCase{Policy::kPartition, "sticky", 2},
                      FallingCase{Policy::kPartition, "sticky", 3},
                      FallingCase{Policy::kWorksteal, "", 2},
                      FallingCase{Policy::kWorksteal, "", 3}),
    [](const auto& p) {
      return std::string(to_string(p.param.policy)) + p.param.method +
             std::to_string(p.param.threads);
    });

TEST(Live, EveryPolicyAndThreadCountMatchesItsReferenceOnBarsAndCloth) {
#if defined(__SANITIZE_THREAD__)
  // Under TSan (scripts/test's tsan block) two threads only: the whole matrix took 9 minutes
  // there, counts 2 and 3 three and a half. Three threads run under TSan in
  // FallingLive/partitionsticky3 and the adapter's roundrobin_3.
  const std::uint32_t first = 2, last = 2;
#else
  const std::uint32_t first = 1, last = 4;
#endif
  for (const char* scene : {"bars64", "cloth128"})
    for (Policy p : {Policy::kPartition, Policy::kWorksteal, Policy::kBarrier, Policy::kOmpTasks})
      for (std::uint32_t k = first; k <= last; ++k) {
        // omp-tasks at 2 threads only: its thread counts are covered on random graphs
        // (executor_test), and libgomp's per-task cost makes whole scenes slow under TSan.
        if (p == Policy::kOmpTasks && k != 2) continue;
        const LiveResult r = live(scene, p, "owner", k, 2);
        EXPECT_EQ(r.check, Check::kIdentical) << scene << " " << to_string(p) << " k=" << k << ": "
                                              << (r.difference ? r.difference->datum : "");
        EXPECT_FALSE(r.steps[0].loop_iterations.empty());
        EXPECT_GT(r.steps[0].loop_iterations[0], 1u) << "the CG loop ran one iteration";
      }
}

TEST(Live, SerializedReductionsMatchThePlainProgramOrder) {
  const LiveResult r = live("bars64", Policy::kPartition, "metis", 2, 2, CwMode::kSerialize);
  EXPECT_EQ(r.cw, CwMode::kSerialize);
  EXPECT_EQ(r.check, Check::kIdentical);
  EXPECT_NE(r.reference.find("program order"), std::string::npos);
}

// Physics, not bits: parallel reductions change the order of additions only, so positions
// after a few implicit steps agree with the uninstrumented engine to rounding level.
TEST(Live, ParallelReductionsLeaveThePhysicsWithinRounding) {
  auto plain = make_live_engine("bars64");
  auto engine = make_live_engine("bars64");
  ExecOptions eo;
  eo.threads = 2;
  auto ex = make_executor(Policy::kPartition, eo);
  const partition::StepPartitioner p = partitioner_for("owner");
  LiveStep cur;
  ProgramWorkload w;
  Assignment a;
  for (int s = 0; s < 3; ++s) {
    plain->plain_step();
    LiveStep next = engine->record_step(true);
    if (!next.reuse_previous) {
      cur = std::move(next);
      for (Task& t : cur.graph.tasks) t.cost_ns = 1;
      a = p(cur.graph, 2, nullptr, nullptr);
    }
    w.set_program(cur.bodies, cur.conditions, cur.accumulators);
    ex->run_step(cur.graph, &a, w);
  }
  EXPECT_FALSE(ex->last_exec()->reductions.empty()) << "no reduction ran in parallel";
  const auto want = plain->state(), got = engine->state();
  ASSERT_EQ(want.size(), got.size());
  double max_rel = 0;
  std::size_t compared = 0;
  bool differs = false;
  for (std::size_t i = 0; i < want.size(); ++i) {
    const std::string& name = want[i].name;
    if (name.size() < 2 || name.compare(name.size() - 2, 2, ".x") != 0) continue;
    const auto* x = static_cast<const double*>(want[i].ptr);
    const auto* y = static_cast<const double*>(got[i].ptr);
    for (std::uint64_t j = 0; j < want[i].bytes / 8; ++j) {
      max_rel = std::max(max_rel, std::abs(x[j] - y[j]) / std::max(1.0, std::abs(x[j])));
      differs = differs || x[j] != y[j];
      ++compared;
    }
  }
  EXPECT_GT(compared, 10'000u);
  EXPECT_LT(max_rel, 1e-9);
  (void)differs;  // bitwise equality is not expected (another summation order)
}

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
  EXPECT_EQ(to_string(*diff), "first differing datum v (byte 8, 1 bytes differ)");
}

// The first step is placed by the owner rule before any cost is measured (every task 1 ns),
// without calling the partitioner; the second partitions afresh from measured costs, and only
// the later steps start from the previous one. In the foreground every call's assignment is
// the one its step runs.
TEST(Live, PartitionsAfreshOnceCostsAreMeasuredThenFromThePreviousStep) {
  struct Call {
    bool from_prev;
    bool unit_costs;
  };
  std::vector<Call> calls;
  std::shared_ptr<partition::Strategy> sticky = partition::make_strategy("sticky");
  const partition::StepPartitioner p = [&](const StepGraph& g, std::uint32_t k,
                                           const StepGraph* pg, const Assignment* pa) {
    const bool unit = std::all_of(g.tasks.begin(), g.tasks.end(),
                                  [](const Task& t) { return t.cost_ns == 1; });
    calls.push_back({pg != nullptr, unit});
    return sticky->partition(g, k, partition::Previous{pg, pa}, {}).assignment;
  };
  LiveOptions o = quiet_options(2, 5);
  o.repartition_every_step = true;  // a call at every step but the first
  o.background_partition = false;
  const LiveResult r = run_live([] { return make_live_engine("bars64"); }, &p, o);
  ASSERT_EQ(calls.size(), 4u);
  EXPECT_FALSE(calls[0].unit_costs);
  EXPECT_FALSE(calls[0].from_prev);
  for (std::size_t i = 1; i < calls.size(); ++i) {
    EXPECT_FALSE(calls[i].unit_costs) << i;
    EXPECT_TRUE(calls[i].from_prev) << i;
  }
  for (const LiveStepMeasure& m : r.steps) EXPECT_TRUE(m.partitioned);
  EXPECT_EQ(r.steps[0].background_partition_ns, 0);
  EXPECT_GT(r.steps[1].background_partition_ns, 0);
}

// An engine that counts the steps it recorded.
class CountingEngine : public LiveEngine {
 public:
  CountingEngine(std::unique_ptr<LiveEngine> e, std::atomic<std::uint32_t>& recorded)
      : e_(std::move(e)), recorded_(recorded) {}
  LiveStep record_step(bool allow_reuse) override {
    LiveStep s = e_->record_step(allow_reuse);
    recorded_.fetch_add(1);
    return s;
  }
  void plain_step() override { e_->plain_step(); }
  std::vector<StateRegion> state() const override { return e_->state(); }

 private:
  std::unique_ptr<LiveEngine> e_;
  std::atomic<std::uint32_t>& recorded_;
};

// In the background (the default) the partitioner runs on another thread and no step waits
// for it: a partitioner that returns only once every step was recorded lets the run finish,
// the steps keep the owner rule's assignment meanwhile, and the state is the sequential
// run's of the same assignments.
TEST(Live, NoStepWaitsForABackgroundPartitioner) {
  std::atomic<std::uint32_t> recorded{0};
  std::vector<std::thread::id> callers;
  bool timed_out = false;
  std::shared_ptr<partition::Strategy> metis = partition::make_strategy("metis");
  const partition::StepPartitioner p = [&](const StepGraph& g, std::uint32_t k,
                                           const StepGraph* pg, const Assignment* pa) {
    callers.push_back(std::this_thread::get_id());
    // Generous: under ThreadSanitizer on a loaded machine six steps take tens of seconds.
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(300);
    while (recorded.load() < 6 && std::chrono::steady_clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    if (recorded.load() < 6) timed_out = true;
    return metis->partition(g, k, partition::Previous{pg, pa}, {}).assignment;
  };
  LiveOptions o = quiet_options(2, 6);
  o.check = true;
  const LiveResult r = run_live(
      [&] { return std::make_unique<CountingEngine>(make_live_engine("bars64"), recorded); }, &p,
      o);
  EXPECT_FALSE(timed_out);
  ASSERT_FALSE(callers.empty());
  for (const std::thread::id& id : callers) EXPECT_NE(id, std::this_thread::get_id());
  EXPECT_TRUE(r.steps[0].partitioned);
  // Until the last step was recorded the partitioner cannot have returned.
  for (std::size_t s = 2; s + 1 < r.steps.size(); ++s) EXPECT_FALSE(r.steps[s].reassigned) << s;
  EXPECT_GT(r.steps.back().background_partition_ns, 0);
  ASSERT_TRUE(r.check.has_value());
  EXPECT_EQ(*r.check, Check::kIdentical);
}

TEST(Live, RefusesThePartitionPolicyWithoutAPartitioner) {
  LiveOptions o;
  o.policy = Policy::kPartition;
  EXPECT_THROW(run_live([] { return make_live_engine("fig2"); }, nullptr, o), UsageError);
}

}  // namespace
}  // namespace tgraph::measure
