// SPDX-License-Identifier: MIT
// tgraph::replay: every policy this installation has (StarPU's too, when built with it) runs
// real bodies on two threads; the sum task must see every scale task's result.
#include <atomic>
#include <chrono>
#include <cstdio>

#include "fork_join.hpp"
#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/lowering.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/workload.hpp"

namespace {

// x_i = i + 1 after a short spin (so that a missing dependency would let `sum` run early),
// then total = sum of x_i.
class Bodies : public tgraph::replay::Workload {
 public:
  std::vector<std::atomic<long>> x = std::vector<std::atomic<long>>(consumer::kWidth);
  std::atomic<long> total{0};
  void run(const tgraph::replay::TaskRun& r) override {
    if (r.origin == tgraph::kNoTask) return;  // no reducers: the graph has no CW
    if (r.origin < consumer::kWidth) {
      const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(200);
      while (std::chrono::steady_clock::now() < until) {
      }
      // relaxed: the executor's dependency edge orders this before `sum`'s reads.
      x[r.origin].store(r.origin + 1, std::memory_order_relaxed);
      return;
    }
    long s = 0;
    for (auto& v : x) s += v.load(std::memory_order_relaxed);
    total.store(s, std::memory_order_relaxed);
  }
  bool stop_after(tgraph::LoopId, std::uint32_t) override { return true; }
};

}  // namespace

int main() {
  using consumer::expect;
  using tgraph::replay::Policy;
  const tgraph::StepGraph g = consumer::fork_join();
  tgraph::Assignment a;
  a.k = 2;
  for (tgraph::TaskId t = 0; t < g.tasks.size(); ++t) a.proc.push_back(t % 2);
  std::vector<Policy> policies = {Policy::kSequential, Policy::kPartition, Policy::kWorksteal,
                                  Policy::kBarrier};
#ifdef TGRAPH_HAVE_STARPU
  policies.push_back(Policy::kStarpu);
#endif
  for (Policy policy : policies) {
    tgraph::replay::ExecOptions options;
    options.threads = policy == Policy::kSequential ? 1 : 2;
    options.pin = false;
    auto executor = tgraph::replay::make_executor(policy, options);
    for (int step = 0; step < 3; ++step) {
      Bodies bodies;
      const tgraph::replay::ExecStepStats s = executor->run_step(g, &a, bodies);
      const std::string name(tgraph::replay::to_string(policy));
      expect(bodies.total.load() == consumer::kWidth * (consumer::kWidth + 1) / 2,
             name + ": the sum task saw every scale task");
      expect(s.wall_ns > 0, name + ": wall time");
    }
    std::printf("replay %s: ok\n", std::string(tgraph::replay::to_string(policy)).c_str());
  }
  return 0;
}
