// SPDX-License-Identifier: MIT
// Strategies side by side on each scene's step graph, plus the simulator: `partition_bench`.
//
//  * Partition/<graph>/<method>/k:K: Strategy::partition from scratch (no previous step).
//    Counters: tasks, predicted_speedup (work / simulated makespan of the result).
//  * StickyReuse/<graph>/k:K: sticky on an unchanged step given its own previous assignment
//    (the path the paper relies on while the structure repeats).
//  * Simulate/<graph>/k:K: the simulator on owner's assignment (items: task instances).
//
// Graphs: step 3 of the scenes bars64, cloth128, falling and torso (captured at start-up,
// edges derived), `synthetic` (a bars-like step: 64 objects with per-object chains in a
// CG-like loop with global dot products), and the STG graph given by TGRAPH_BENCH_STG.
// Sticky after a contact change against a full METIS: incremental_bench (FallingPartition).
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "bench_main.hpp"
#include "tgraph/capture/recorder.hpp"
#include "tgraph/graph/metrics.hpp"
#include "tgraph/graph/stg.hpp"
#include "tgraph/partition/simulator.hpp"
#include "tgraph/partition/strategy.hpp"
#include "tgraph/samples/scene.hpp"

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
    task(static_cast<ObjectId>(i),
         {{alpha, AccessMode::R}, {q[i], AccessMode::R}, {p[i], AccessMode::RW}}, 400);
  task(kNoObject, {{cond, AccessMode::R}}, 50);
  const auto last = static_cast<TaskId>(g.tasks.size());
  for (TaskId t = first; t < last; ++t) g.tasks[t].loop = 0;
  g.loops.push_back({cond, first, last, 25, 200});
  g.derive_edges();
  return g;
}

/// The step graph called `name` (built once).
const StepGraph& graph(const std::string& name) {
  static std::map<std::string, StepGraph> cache;
  auto it = cache.find(name);
  if (it != cache.end()) return it->second;
  StepGraph g;
  if (name == "synthetic") {
    g = bars_like(64);
  } else if (name == "stg") {
    g = read_stg(std::getenv("TGRAPH_BENCH_STG")).trace.steps[0];
  } else {
    auto scene = samples::make_scene(name);
    capture::Recorder rec(capture::Mode::kCapture);
    for (int s = 0; s < 4; ++s) {
      scene->step(rec);
      g = rec.end_step();
    }
  }
  return cache.emplace(name, std::move(g)).first->second;
}

void BM_Partition(benchmark::State& state, const std::string& name, const std::string& method) {
  const StepGraph& g = graph(name);
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
  state.counters["predicted_speedup"] =
      static_cast<double>(m.work_ns) / static_cast<double>(sched.makespan_ns);
}

// Sticky on an unchanged step: the reuse path the paper relies on.
void BM_StickyReuse(benchmark::State& state, const std::string& name) {
  const StepGraph& g = graph(name);
  const auto k = static_cast<std::uint32_t>(state.range(0));
  auto s = make_strategy("sticky");
  const Result first = s->partition(g, k, {}, {});
  for (auto _ : state) {
    Result r = s->partition(g, k, {&g, &first.assignment}, {});
    benchmark::DoNotOptimize(r.assignment.proc.data());
  }
}

void BM_Simulate(benchmark::State& state, const std::string& name) {
  const StepGraph& g = graph(name);
  const Result r =
      make_strategy("owner")->partition(g, static_cast<std::uint32_t>(state.range(0)), {}, {});
  std::uint64_t instances = 0;
  for (auto _ : state) {
    const Schedule s = simulate(g, r.assignment, CostModel::defaults());
    instances = s.first_instance.back();
    benchmark::DoNotOptimize(s.makespan_ns);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(instances) * state.iterations());
}

void register_all(bench::Size size) {
  std::vector<std::string> graphs = {"bars64", "cloth128", "falling", "torso", "synthetic"};
  if (std::getenv("TGRAPH_BENCH_STG") != nullptr) graphs.push_back("stg");
  if (size == bench::Size::kSmoke) graphs = {"synthetic"};
  const std::vector<std::string> methods = {"owner", "metis", "scotch", "list", "roundrobin"};
  const std::vector<int> ks = bench::by_size<std::vector<int>>(size, {2}, {2, 16}, {2, 8, 32});
  for (const std::string& g : graphs) {
    for (const std::string& m : methods) {
      auto* b =
          benchmark::RegisterBenchmark(("BM_Partition/" + g + "/" + m).c_str(), BM_Partition, g, m)
              ->ArgName("k")
              ->Unit(benchmark::kMicrosecond);
      for (int k : ks) b->Arg(k);
      bench::timed(b, size, 0.05);
    }
    auto* sticky = benchmark::RegisterBenchmark(("BM_StickyReuse/" + g).c_str(), BM_StickyReuse, g)
                       ->ArgName("k")
                       ->Unit(benchmark::kMicrosecond);
    auto* sim = benchmark::RegisterBenchmark(("BM_Simulate/" + g).c_str(), BM_Simulate, g)
                    ->ArgName("k")
                    ->Unit(benchmark::kMicrosecond);
    for (int k : ks) {
      sticky->Arg(k);
      sim->Arg(k);
    }
    bench::timed(sticky, size, 0.05);
    bench::timed(sim, size, 0.05);
  }
}

}  // namespace

int main(int argc, char** argv) { return tgraph::bench::run_main(argc, argv, register_all); }
