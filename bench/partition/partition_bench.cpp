// SPDX-License-Identifier: MIT
// Strategies side by side on each scene's step graph, plus the simulator: `partition_bench`.
//
//  * Partition/<graph>/<method>/k:K: Strategy::partition from scratch (no previous step).
//    Counters: tasks, predicted_speedup (work / simulated makespan of the result).
//  * StickyReuse/<graph>/k:K: sticky on an unchanged step given its own previous assignment
//    (the path the paper relies on while the structure repeats).
//  * Simulate/<graph>/k:K: the simulator on owner's assignment (items: task instances).
//  * SimulateCluster/stencil:<tasks>/<engine>/nodes:N: `tgraph simulate` on a generated
//    stencil step (rows of 1,024 tasks, each reading its three neighbours of the previous
//    row, 10-50 us, 4 KiB per datum), column c on processor c of N x 16 cores (1,024
//    processors: 64 nodes x 16 cores at N = 64); builtin against SimGrid (when built).
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
#include "tgraph/model/simulation.hpp"
#include "tgraph/model/simulator.hpp"
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
  const model::Schedule sched = model::simulate(g, r.assignment, model::CostModel::defaults());
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
    const model::Schedule s = model::simulate(g, r.assignment, model::CostModel::defaults());
    instances = s.first_instance.back();
    benchmark::DoNotOptimize(s.makespan_ns);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(instances) * state.iterations());
}

// `rows` rows of `width` tasks; task (r, c) writes its datum and reads those of (r - 1,
// c - 1..c + 1). Costs 10-50 us from a fixed pseudo-random sequence.
StepGraph stencil(int width, int rows) {
  StepGraph g;
  g.kinds = {"op"};
  std::uint64_t seed = 12345;
  StableKey key = 1;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < width; ++c) {
      std::string name = "v";
      name += std::to_string(r * width + c);
      g.data.push_back({name, kNoObject, 4096});
      std::vector<Access> acc{{static_cast<DatumId>(g.data.size() - 1), AccessMode::W}};
      for (int dc = -1; dc <= 1 && r > 0; ++dc)
        if (c + dc >= 0 && c + dc < width)
          acc.push_back({static_cast<DatumId>((r - 1) * width + c + dc), AccessMode::R});
      seed = seed * 6364136223846793005ull + 1442695040888963407ull;
      g.add_task(0, kNoObject, acc, 10000 + (seed >> 33) % 40001, key++);
    }
  g.derive_edges();
  return g;
}

void BM_SimulateCluster(benchmark::State& state, int rows, model::SimulationEngine engine) {
  constexpr int kWidth = 1024;
  constexpr std::uint32_t kCores = 16;
  Trace trace;
  trace.steps = {stencil(kWidth, rows)};
  TraceAssignment a;
  a.k = kWidth;
  a.steps.push_back({kWidth, {}, {}});
  for (std::size_t t = 0; t < trace.steps[0].tasks.size(); ++t)
    a.steps[0].proc.push_back(static_cast<ProcId>(t % kWidth));
  model::SimulatedPlatform p;
  p.cluster = model::ClusterShape{static_cast<std::uint32_t>(state.range(0)), kCores};
  p.model = model::CostModel::defaults();
  std::uint64_t makespan = 0;
  for (auto _ : state) makespan = model::simulate_trace(trace, a, engine, p).makespan_ns;
  state.counters["makespan_ms"] = static_cast<double>(makespan) / 1e6;
  state.SetItemsProcessed(static_cast<std::int64_t>(trace.steps[0].tasks.size()) * state.iterations());
}

void register_all(bench::Size size) {
  const int rows = bench::by_size(size, 2, 20, 100);
  for (model::SimulationEngine e :
       {model::SimulationEngine::builtin, model::SimulationEngine::simgrid}) {
    if (e == model::SimulationEngine::simgrid && !model::simgrid_available()) continue;
    auto* b = benchmark::RegisterBenchmark(
                  ("BM_SimulateCluster/stencil:" + std::to_string(rows * 1024) + "/" + to_string(e))
                      .c_str(),
                  BM_SimulateCluster, rows, e)
                  ->ArgName("nodes")
                  ->Unit(benchmark::kMillisecond)
                  ->UseRealTime();  // SimGrid runs in a child process
    b->Arg(64)->Arg(1024);
    bench::timed(b, size, 0.05);
  }
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
