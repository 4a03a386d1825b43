// SPDX-License-Identifier: MIT
// The omp-tasks policy against the same graph written by hand with OpenMP tasks, side by side
// in one run, on the steps of a captured trace (default tests/data/traces/bars64.tgt;
// TGRAPH_BENCH_TRACE names another):
//  * OmpHandwritten/threads:N: what an OpenMP user writes for the trace's program, with no
//    tgraph executor in between: one `omp parallel` + `omp single` per step, one
//    `omp task depend(...)` per task instance in program order (R -> in, W -> out, RW ->
//    inout, CW -> mutexinoutset: the writers of a sum in any order, one at a time), the
//    dependence objects one per datum, and a `taskwait` after each iteration of a loop (the
//    convergence test reads the residual), its recorded count of iterations. Bodies are the
//    replay's synthetic ones (SyntheticWorkload: the recorded cost, the data's memory pass).
//  * OmpTasksPolicy/threads:N: `--policy omp-tasks` (make_executor, its defaults: per-writer
//    temporaries) on the same steps and bodies; OmpTasksPolicyMutex: the same with the CW
//    groups whole, declared mutexinoutset as by hand (reduce scope none); OmpTasksPolicyPerThread:
//    one temporary per thread (reduce scope per-thread).
// Time per benchmark iteration: one pass over every step of the trace.
//
//   omp_handwritten_bench --benchmark_repetitions=5 --benchmark_enable_random_interleaving=true
#include <omp.h>

#include <cstdlib>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bench_main.hpp"
#include "tgraph/graph/lowering.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/synthetic.hpp"

namespace tgraph::replay {
namespace {

const Trace& trace() {
  static const Trace t = [] {
    const char* path = std::getenv("TGRAPH_BENCH_TRACE");
    return read_trace(path != nullptr ? path : TGRAPH_BENCH_DEFAULT_TRACE);
  }();
  return t;
}

/// One step written by hand: its dependence lists by mode, and the graph the synthetic bodies
/// read (the step itself: nothing lowered, no temporaries).
struct HandStep {
  ExecGraph x;
  std::vector<std::vector<int>> in, out, inout, mutex;  // by task: datum ids
};

HandStep prepare(const StepGraph& g) {
  HandStep h;
  h.x = lower(g, nullptr, CwMode::kReduce, ReduceScope::kNone);
  const std::size_t n = g.tasks.size();
  h.in.resize(n);
  h.out.resize(n);
  h.inout.resize(n);
  h.mutex.resize(n);
  // A datum named twice by one task is one dependence, RW where the modes differ.
  std::map<DatumId, AccessMode> mode;
  for (TaskId t = 0; t < n; ++t) {
    mode.clear();
    for (const Access& a : g.accesses_of(t)) {
      const auto [it, fresh] = mode.emplace(a.datum, a.mode);
      if (!fresh && it->second != a.mode) it->second = AccessMode::RW;
    }
    for (const auto& [datum, m] : mode) {
      auto& list = m == AccessMode::R    ? h.in[t]
                   : m == AccessMode::W  ? h.out[t]
                   : m == AccessMode::RW ? h.inout[t]
                                         : h.mutex[t];
      list.push_back(static_cast<int>(datum));
    }
  }
  return h;
}

/// The task of instance (t, it): its dependences from the step's accesses, its body the
/// replay's.
void submit(const HandStep* h, SyntheticWorkload* w, char* obj, TaskId t, std::uint32_t it) {
  const int* in = h->in[t].data();
  const int* out = h->out[t].data();
  const int* inout = h->inout[t].data();
  const int* mutex = h->mutex[t].data();
  const int n_in = static_cast<int>(h->in[t].size()), n_out = static_cast<int>(h->out[t].size()),
            n_inout = static_cast<int>(h->inout[t].size()),
            n_mutex = static_cast<int>(h->mutex[t].size());
  (void)obj;  // GCC 12 warns it unused when only iterator clauses read it
#pragma omp task firstprivate(h, w, t, it)                    \
    depend(iterator(i = 0 : n_in), in : obj[in[i]])           \
    depend(iterator(i = 0 : n_out), out : obj[out[i]])        \
    depend(iterator(i = 0 : n_inout), inout : obj[inout[i]])  \
    depend(iterator(i = 0 : n_mutex), mutexinoutset : obj[mutex[i]])
  w->run(TaskRun{&h->x, t, t, it, static_cast<std::uint32_t>(omp_get_thread_num())});
}

/// The hand-written program of one step.
void run_by_hand(const HandStep& h, SyntheticWorkload& w, int threads) {
  const StepGraph& g = h.x.graph;
  std::vector<char> dep(g.data.size() + 1);
  char* obj = dep.data();
  const auto task = [&](TaskId t, std::uint32_t it) { submit(&h, &w, obj, t, it); };
#pragma omp parallel num_threads(threads)
#pragma omp single
  {
    std::size_t next_loop = 0;
    for (TaskId t = 0; t < g.tasks.size();) {
      if (next_loop < g.loops.size() && g.loops[next_loop].first == t) {
        const Loop& loop = g.loops[next_loop++];
        for (std::uint32_t it = 0; it < loop.iterations; ++it) {
          for (TaskId u = loop.first; u < loop.last; ++u) task(u, it);
#pragma omp taskwait
        }
        t = loop.last;
        continue;
      }
      task(t++, 0);
    }
  }
}

void BM_OmpHandwritten(benchmark::State& state) {
  const auto k = static_cast<int>(state.range(0));
  const Trace& tr = trace();
  std::vector<HandStep> steps;
  for (const StepGraph& g : tr.steps) steps.push_back(prepare(g));
  std::vector<std::unique_ptr<SyntheticWorkload>> ws;
  for (std::size_t s = 0; s < steps.size(); ++s) {
    ws.push_back(std::make_unique<SyntheticWorkload>());
    ws[s]->set_step(tr.steps[s]);
    ws[s]->bind(steps[s].x);
    for (DatumId d = 0; d < steps[s].x.graph.data.size(); ++d)
      if (ws[s]->needs_touch(d)) ws[s]->first_touch(d);
  }
  for (std::size_t s = 0; s < steps.size(); ++s) run_by_hand(steps[s], *ws[s], k);  // warm-up
  for (auto _ : state)
    for (std::size_t s = 0; s < steps.size(); ++s) run_by_hand(steps[s], *ws[s], k);
  state.counters["steps"] = static_cast<double>(steps.size());
}

void BM_OmpTasksPolicy(benchmark::State& state, std::optional<ReduceScope> scope) {
  const Trace& tr = trace();
  ExecOptions o;
  o.threads = static_cast<std::uint32_t>(state.range(0));
  o.reduce_scope = scope;
  auto ex = make_executor(Policy::kOmpTasks, o);
  std::vector<std::unique_ptr<SyntheticWorkload>> ws;
  for (const StepGraph& g : tr.steps) {
    ws.push_back(std::make_unique<SyntheticWorkload>());
    ws.back()->set_step(g);
  }
  for (std::size_t s = 0; s < tr.steps.size(); ++s) ex->run_step(tr.steps[s], nullptr, *ws[s]);
  for (auto _ : state)
    for (std::size_t s = 0; s < tr.steps.size(); ++s) ex->run_step(tr.steps[s], nullptr, *ws[s]);
  state.counters["steps"] = static_cast<double>(tr.steps.size());
}

void register_all(bench::Size size) {
  const std::vector<std::int64_t> threads =
      size == bench::Size::kSmoke ? std::vector<std::int64_t>{2} : std::vector<std::int64_t>{1, 2};
  for (auto* b :
       {benchmark::RegisterBenchmark("BM_OmpHandwritten", BM_OmpHandwritten),
        benchmark::RegisterBenchmark("BM_OmpTasksPolicy", BM_OmpTasksPolicy, std::nullopt),
        benchmark::RegisterBenchmark("BM_OmpTasksPolicyMutex", BM_OmpTasksPolicy, ReduceScope::kNone),
        benchmark::RegisterBenchmark("BM_OmpTasksPolicyPerThread", BM_OmpTasksPolicy,
                                     ReduceScope::kPerThread)}) {
    b->ArgName("threads")->Unit(benchmark::kMillisecond)->UseRealTime();
    for (const std::int64_t t : threads) b->Arg(t);
    bench::timed(b, size, 1.0);
  }
}

}  // namespace
}  // namespace tgraph::replay

int main(int argc, char** argv) {
  return tgraph::bench::run_main(argc, argv, tgraph::replay::register_all);
}
