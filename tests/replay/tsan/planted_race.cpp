// SPDX-License-Identifier: MIT
// A race planted in an executor's own state, for tsan_race_test (tsan preset only): two
// threads run steps on one executor at once, so that the executor's per-step state (its
// thread counters, reset by the caller and written by every thread of its region, and the
// step context its tasks read) is written by both steps' threads with nothing ordering them.
// An executor is not meant to be shared that way; TSan must say so, naming the executor,
// whatever tests/replay/tsan_suppressions.cpp leaves out. "apart" runs the same steps one
// thread after the other (joined in between): the same code, no race.
//
//   tsan_planted_race barrier|omp-tasks together|apart
#include <atomic>
#include <chrono>
#include <cstdio>
#include <optional>
#include <string_view>
#include <thread>
#include <vector>

#include "tgraph/graph/step_graph.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/policy.hpp"
#include "tgraph/replay/workload.hpp"

namespace {

using namespace tgraph;
using namespace tgraph::replay;

/// Bodies that touch nothing and take 100 µs each, so that two threads' steps overlap: the
/// only shared state of two concurrent steps is the executor's.
class BusyWorkload final : public Workload {
 public:
  void run(const TaskRun&) override {
    const auto end = std::chrono::steady_clock::now() + std::chrono::microseconds(100);
    while (std::chrono::steady_clock::now() < end) {
    }
  }
  bool stop_after(LoopId, std::uint32_t) override { return true; }
};

/// 16 independent tasks of one kind, each writing a datum of its own: one phase for the
/// barrier policy, 16 tasks with no dependence for omp-tasks.
StepGraph independent_tasks() {
  StepGraph g;
  const KindId kind = g.intern_kind("t");
  for (int i = 0; i < 16; ++i) {
    g.objects.push_back({"o" + std::to_string(i)});
    g.data.push_back({"d" + std::to_string(i), static_cast<ObjectId>(i), 8});
    g.add_task(kind, static_cast<ObjectId>(i),
               std::vector<Access>{{static_cast<DatumId>(i), AccessMode::W}}, 0,
               static_cast<StableKey>(i + 1));
  }
  g.derive_edges();
  return g;
}

}  // namespace

int main(int argc, char** argv) {
  const std::optional<Policy> policy = argc == 3 ? parse_policy(argv[1]) : std::nullopt;
  const std::string_view mode = argc == 3 ? argv[2] : "";
  if (!policy || (mode != "together" && mode != "apart")) {
    std::fprintf(stderr, "usage: tsan_planted_race barrier|omp-tasks together|apart\n");
    return 2;
  }
  const StepGraph g = independent_tasks();
  ExecOptions o;
  o.threads = 2;
  o.pin = false;
  auto ex = make_executor(*policy, o);
  BusyWorkload w;
  ex->run_step(g, nullptr, w);  // the plan is built and bound here, before the threads
  const auto steps = [&] {
    for (int s = 0; s < 20; ++s) ex->run_step(g, nullptr, w);
  };
  // relaxed: the two threads meet before their steps without ordering anything for TSan.
  std::atomic<int> started{0};
  const auto meet_then_steps = [&] {
    started.fetch_add(1, std::memory_order_relaxed);
    while (started.load(std::memory_order_relaxed) < 2) {
    }
    steps();
  };
  if (mode == "together") {
    std::thread a(meet_then_steps), b(meet_then_steps);
    a.join();
    b.join();
  } else {
    std::thread a(steps);
    a.join();
    std::thread b(steps);
    b.join();
  }
  return 0;
}
