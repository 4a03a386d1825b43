// SPDX-License-Identifier: MIT
// One pinning rule for every policy (ExecOptions::pin): read from inside the task bodies, each
// thread of a step is bound to one core of its own, its slot's, when pinning is on, and to
// every core the process may use when it is off, even after a pinned executor of the same
// runtime left its pool threads bound.
#include <gtest/gtest.h>
#include <sched.h>

#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/synthetic.hpp"
#include "tgraph/replay/thread_binding.hpp"

namespace tgraph::replay {
namespace {

/// The CPUs the calling thread may run on.
std::set<int> own_affinity() {
  cpu_set_t set;
  CPU_ZERO(&set);
  std::set<int> cpus;
  if (sched_getaffinity(0, sizeof set, &set) != 0) return cpus;  // 0: the calling thread
  for (int c = 0; c < CPU_SETSIZE; ++c)
    if (CPU_ISSET(c, &set)) cpus.insert(c);
  return cpus;
}

/// Synthetic bodies that also record, per executor thread slot, the affinity of the thread
/// running each task, read at the task's start.
class AffinityWorkload : public SyntheticWorkload {
 public:
  AffinityWorkload() : SyntheticWorkload({.cost_scale = 1.0, .touch = false}) {}
  void run(const TaskRun& r) override {
    std::set<int> cpus = own_affinity();
    {
      std::lock_guard lock(mutex_);
      seen_[r.thread].insert(std::move(cpus));
    }
    SyntheticWorkload::run(r);
  }
  /// Slot -> the distinct affinities its tasks saw.
  std::map<std::uint32_t, std::set<std::set<int>>> seen() const {
    std::lock_guard lock(mutex_);
    return seen_;
  }

 private:
  mutable std::mutex mutex_;
  std::map<std::uint32_t, std::set<std::set<int>>> seen_;
};

/// 16 independent tasks of 300 µs (each writes its own datum): work for every thread.
StepGraph wide_step() {
  StepGraph g;
  const KindId k = g.intern_kind("work");
  for (int i = 0; i < 16; ++i) {
    g.objects.push_back({"o" + std::to_string(i)});
    g.data.push_back({"d" + std::to_string(i), static_cast<ObjectId>(i), 64});
    g.add_task(k, static_cast<ObjectId>(i),
               std::vector<Access>{{static_cast<DatumId>(i), AccessMode::W}}, 300'000,
               static_cast<StableKey>(i + 1));
  }
  g.derive_edges();
  return g;
}

/// Two steps of the wide step under `policy` at 2 threads; the affinities seen per slot.
std::map<std::uint32_t, std::set<std::set<int>>> affinities(Policy policy, bool pin) {
  const StepGraph g = wide_step();
  Assignment a;
  a.k = 2;
  for (TaskId t = 0; t < g.tasks.size(); ++t) a.proc.push_back(t % 2);
  ExecOptions o;
  o.threads = 2;
  o.pin = pin;
  auto ex = make_executor(policy, o);
  AffinityWorkload w;
  w.set_step(g);
  for (int s = 0; s < 2; ++s) ex->run_step(g, policy == Policy::kPartition ? &a : nullptr, w);
  return w.seen();
}

std::vector<Policy> threaded_policies() {
  std::vector<Policy> p = {Policy::kPartition, Policy::kWorksteal, Policy::kBarrier,
                           Policy::kOmpTasks};
#if defined(TGRAPH_HAVE_STARPU)
  p.push_back(Policy::kStarpu);
#endif
  return p;
}

class Pinning : public ::testing::TestWithParam<Policy> {};

TEST_P(Pinning, EveryThreadRunsItsTasksOnItsSlotsCoreAloneWhenOn) {
  if (hardware_pus() < 2) GTEST_SKIP() << "needs two processing units";
  ASSERT_NE(pinned_pu(0), pinned_pu(1));
  const auto seen = affinities(GetParam(), true);
  ASSERT_FALSE(seen.empty());
  for (const auto& [slot, sets] : seen) {
    ASSERT_LT(slot, 2u);
    // One affinity per slot over both steps (bound once, never moved), one core in it.
    ASSERT_EQ(sets.size(), 1u) << "slot " << slot;
    EXPECT_EQ(*sets.begin(), std::set<int>{pinned_pu(slot)}) << "slot " << slot;
  }
}

TEST_P(Pinning, NoThreadIsBoundWhenOffEvenAfterAPinnedRun) {
  if (hardware_pus() < 2) GTEST_SKIP() << "needs two processing units";
  affinities(GetParam(), true);  // leaves the runtime's pool threads bound, if it keeps them
  const auto seen = affinities(GetParam(), false);
  ASSERT_FALSE(seen.empty());
  for (const auto& [slot, sets] : seen)
    for (const std::set<int>& cpus : sets)
      EXPECT_EQ(cpus.size(), hardware_pus()) << "slot " << slot;
}

INSTANTIATE_TEST_SUITE_P(Policies, Pinning, ::testing::ValuesIn(threaded_policies()),
                         [](const auto& p) {
                           std::string n(to_string(p.param));
                           std::erase(n, '-');
                           return n;
                         });

}  // namespace
}  // namespace tgraph::replay
