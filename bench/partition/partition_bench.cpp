// SPDX-License-Identifier: MIT
// Strategies side by side on one graph, plus the simulator: `partition_bench`.
// The graph: a synthetic bars-like step (objects with per-object chains inside a CG-like
// loop with global dot products), or the STG graph given by TGRAPH_BENCH_STG.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "tgraph/graph/metrics.hpp"
#include "tgraph/partition/simulator.hpp"
#include "tgraph/graph/stg.hpp"
#include "tgraph/partition/strategy.hpp"

namespace {

using namespace tgraph;
using namespace tgraph::partition;

// `objects` objects, each: force (outside the loop), then in a 25-iteration loop a
// matrix-vector product, a partial dot product into a shared scalar and an update; a
// scalar task and the break close each iteration.
StepGraph bars_like(int objects) {
  StepGraph g;
  g.kinds = {"op"};
  std::vector<DatumId> x, p, q;
  const auto shared = [&](const char* name) {
    g.data.push_back({name, kNoObject, 8});
    return static_cast<DatumId>(g.data.size() - 1);
  };
  for (int i = 0; i < objects; ++i) {
    std::string n = "bar";
    n += std::to_string(i);
    g.objects.push_back({n});
    const auto o = static_cast<ObjectId>(i);
    for (auto* v : {&x, &p, &q}) {
      g.data.push_back({n + ".v" + std::to_string(v->size()), o, 1536});
      v->push_back(static_cast<DatumId>(g.data.size() - 1));
    }
  }
  const DatumId dot = shared("dot"), alpha = shared("alpha"), cond = shared("cond");
  StableKey key = 1;
  auto task = [&](ObjectId o, std::vector<Access> acc, std::uint64_t cost) {
    return g.add_task(0, o, acc, cost, key++);
  };
  for (int i = 0; i < objects; ++i) task(static_cast<ObjectId>(i), {{x[i], AccessMode::RW}}, 7000);
  const auto first = static_cast<TaskId>(g.tasks.size());
  for (int i = 0; i < objects; ++i) {
    const auto o = static_cast<ObjectId>(i);
    task(o, {{p[i], AccessMode::R}, {q[i], AccessMode::W}}, 7000);
    task(o, {{p[i], AccessMode::R}, {q[i], AccessMode::R}, {dot, AccessMode::CW}}, 300);
  }
  task(kNoObject, {{dot, AccessMode::R}, {alpha, AccessMode::W}, {cond, AccessMode::W}}, 100);
  for (int i = 0; i < objects; ++i)
    task(static_cast<ObjectId>(i), {{alpha, AccessMode::R}, {q[i], AccessMode::R}, {p[i], AccessMode::RW}}, 400);
  task(kNoObject, {{cond, AccessMode::R}}, 50);
  const auto last = static_cast<TaskId>(g.tasks.size());
  for (TaskId t = first; t < last; ++t) g.tasks[t].loop = 0;
  g.loops.push_back({cond, first, last, 25, 200});
  g.derive_edges();
  return g;
}

const StepGraph& graph() {
  static const StepGraph g = [] {
    if (const char* stg = std::getenv("TGRAPH_BENCH_STG")) return read_stg(stg).trace.steps[0];
    return bars_like(64);
  }();
  return g;
}

void BM_Partition(benchmark::State& state, const std::string& method) {
  const StepGraph& g = graph();
  const auto k = static_cast<std::uint32_t>(state.range(0));
  auto s = make_strategy(method);
  Result r;
  for (auto _ : state) {
    r = s->partition(g, k, {}, {});
    benchmark::DoNotOptimize(r.assignment.proc.data());
  }
  const Schedule sched = simulate(g, r.assignment, CostModel::defaults());
  const Metrics m = compute_metrics(g);
  state.counters["tasks"] = static_cast<double>(g.tasks.size());
  state.counters["predicted_speedup"] = static_cast<double>(m.work_ns) / static_cast<double>(sched.makespan_ns);
}

// Sticky on an unchanged step: the reuse path the paper relies on.
void BM_StickyReuse(benchmark::State& state) {
  const StepGraph& g = graph();
  const auto k = static_cast<std::uint32_t>(state.range(0));
  auto s = make_strategy("sticky");
  const Result first = s->partition(g, k, {}, {});
  for (auto _ : state) {
    Result r = s->partition(g, k, {&g, &first.assignment}, {});
    benchmark::DoNotOptimize(r.assignment.proc.data());
  }
}

void BM_Simulate(benchmark::State& state) {
  const StepGraph& g = graph();
  const Result r = make_strategy("owner")->partition(g, static_cast<std::uint32_t>(state.range(0)), {}, {});
  std::uint64_t instances = 0;
  for (auto _ : state) {
    const Schedule s = simulate(g, r.assignment, CostModel::defaults());
    instances = s.first_instance.back();
    benchmark::DoNotOptimize(s.makespan_ns);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(instances) * state.iterations());
}

}  // namespace

BENCHMARK_CAPTURE(BM_Partition, owner, std::string("owner"))->Arg(4)->Arg(16)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Partition, metis, std::string("metis"))->Arg(4)->Arg(16)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Partition, scotch, std::string("scotch"))->Arg(4)->Arg(16)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Partition, list, std::string("list"))->Arg(4)->Arg(16)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Partition, roundrobin, std::string("roundrobin"))->Arg(4)->Arg(16)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_StickyReuse)->Arg(4)->Arg(16)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Simulate)->Arg(4)->Arg(16)->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
