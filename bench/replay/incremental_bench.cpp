// SPDX-License-Identifier: MIT
// What a contact change costs on the dynamic scene `falling` (300 steps, captured once):
// the graph update (edges derived incrementally from the previous step, and from scratch),
// the partition executor's plan rebuild (incremental, and from scratch) at K = 2, 4, 8 on
// sticky's assignments, and the partitioning time of METIS, sticky and sticky with
// `--sticky-fallback repartition` (migration cost 1) on the same steps.
//
//   incremental_bench --benchmark_filter=Falling
//
// Each benchmark iteration goes over every step whose structure differs from the previous
// step's (a contact change) and times that step alone; the counters are, over those
// steps, the median (median_us) and the maximum (max_us) of each step's median over the
// iterations; the benchmark's own time is the sum over the changes. Plan rebuilds are
// timed by the executor (StepStats::rebuild_ns: the per-processor programs, lowering
// excluded; lowering_us is the lowering's median), on a fresh executor that first built
// the previous step's plan. Graph updates alternate between the previous step and the
// changed one, so that each derivation starts from the other step.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <string>
#include <vector>

#include "tgraph/capture/recorder.hpp"
#include "tgraph/graph/incremental.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/partition/strategy.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/synthetic.hpp"
#include "tgraph/samples/scene.hpp"

namespace {

using tgraph::StepGraph;

struct Falling {
  tgraph::Trace trace;
  std::vector<std::size_t> changes;  // steps whose structure differs from the previous one
};

const Falling& falling() {
  static const Falling f = [] {
    Falling r;
    auto scene = tgraph::samples::make_scene("falling");
    tgraph::capture::Recorder rec(tgraph::capture::Mode::kCapture);
    for (int s = 0; s < scene->default_steps(); ++s) {
      scene->step(rec);
      r.trace.steps.push_back(rec.end_step());
    }
    for (std::size_t s = 1; s < r.trace.steps.size(); ++s)
      if (!r.trace.steps[s].same_structure(r.trace.steps[s - 1])) r.changes.push_back(s);
    return r;
  }();
  return f;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : (v[v.size() / 2 - 1] + v[v.size() / 2]) / 2;
}

// Counters from per-change samples (ns): median and max of the per-change medians.
void report(benchmark::State& state, const std::vector<std::vector<double>>& samples,
            const std::string& prefix = "") {
  std::vector<double> med;
  for (const auto& s : samples) med.push_back(median(s));
  state.counters[prefix + "median_us"] = median(med) / 1e3;
  state.counters[prefix + "max_us"] = med.empty() ? 0 : *std::max_element(med.begin(), med.end()) / 1e3;
  state.counters["changes"] = static_cast<double>(samples.size());
}

void BM_FallingGraphUpdate(benchmark::State& state, bool incremental) {
  const Falling& f = falling();
  std::vector<StepGraph> prev, cur;
  std::vector<tgraph::EdgeDeriver> derivers(f.changes.size());
  for (std::size_t i = 0; i < f.changes.size(); ++i) {
    prev.push_back(f.trace.steps[f.changes[i] - 1]);
    cur.push_back(f.trace.steps[f.changes[i]]);
    derivers[i].seed(prev.back());
  }
  std::vector<std::vector<double>> samples(f.changes.size());
  std::uint64_t rederived = 0, accessed = 0, iterations = 0;
  bool forward = true;
  for (auto _ : state) {
    double total = 0;
    for (std::size_t i = 0; i < f.changes.size(); ++i) {
      StepGraph& g = forward ? cur[i] : prev[i];
      double ns = 0;
      if (incremental) {
        const tgraph::EdgeUpdate u = derivers[i].derive(g);
        ns = static_cast<double>(u.ns);
        rederived += u.data_rederived;
        accessed += u.data_rederived + u.data_reused;
      } else {
        const auto t0 = std::chrono::steady_clock::now();
        g.derive_edges();
        ns = static_cast<double>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                     std::chrono::steady_clock::now() - t0)
                                     .count());
      }
      benchmark::DoNotOptimize(g.edges.data());
      samples[i].push_back(ns);
      total += ns;
    }
    forward = !forward;
    ++iterations;
    state.SetIterationTime(total / 1e9);
  }
  report(state, samples);
  if (incremental && accessed > 0)
    state.counters["rederived_data_pct"] = 100.0 * static_cast<double>(rederived) / static_cast<double>(accessed);
}

const tgraph::partition::TracePartition& sticky(std::uint32_t k) {
  static std::map<std::uint32_t, tgraph::partition::TracePartition> cache;
  auto it = cache.find(k);
  if (it == cache.end()) it = cache.emplace(k, tgraph::partition::partition_trace(falling().trace, "sticky", k)).first;
  return it->second;
}

void BM_FallingPlanRebuild(benchmark::State& state, bool incremental) {
  const Falling& f = falling();
  const auto k = static_cast<std::uint32_t>(state.range(0));
  const tgraph::partition::TracePartition& tp = sticky(k);
  tgraph::replay::ExecOptions o;
  o.threads = k;
  o.serial = true;  // the programs are built the same way; the step runs on this thread
  o.pin = false;
  o.incremental_plans = incremental;
  std::vector<std::vector<double>> samples(f.changes.size()), lowering(f.changes.size());
  double procs = 0, plans = 0;
  tgraph::replay::SyntheticWorkload w({.cost_scale = 0.0});
  for (auto _ : state) {
    double total = 0;
    for (std::size_t i = 0; i < f.changes.size(); ++i) {
      const std::size_t s = f.changes[i];
      auto ex = tgraph::replay::make_executor(tgraph::replay::Policy::kPartition, o);
      w.set_step(f.trace.steps[s - 1]);
      ex->run_step(f.trace.steps[s - 1], &tp.assignment.steps[s - 1], w);
      w.set_step(f.trace.steps[s]);
      const tgraph::replay::StepStats st = ex->run_step(f.trace.steps[s], &tp.assignment.steps[s], w);
      samples[i].push_back(static_cast<double>(st.rebuild_ns));
      lowering[i].push_back(static_cast<double>(st.build_ns - st.rebuild_ns));
      procs += st.rebuilt_procs;
      plans += 1;
      total += static_cast<double>(st.rebuild_ns);
    }
    state.SetIterationTime(total / 1e9);
  }
  report(state, samples);
  report(state, lowering, "lowering_");
  state.counters["rebuilt_procs"] = plans > 0 ? procs / plans : 0;
}

void BM_FallingPartition(benchmark::State& state, const char* method, bool repartition) {
  const Falling& f = falling();
  const auto k = static_cast<std::uint32_t>(state.range(0));
  tgraph::partition::Options options;
  if (repartition) options.sticky_fallback = tgraph::partition::StickyFallback::kRepartition;
  std::vector<std::vector<double>> samples(f.changes.size());
  std::vector<double> totals;
  for (auto _ : state) {
    const tgraph::partition::TracePartition tp = tgraph::partition::partition_trace(f.trace, method, k, options);
    double total = 0, changes = 0;
    for (const auto& st : tp.stats) total += st.partition_ms;
    for (std::size_t i = 0; i < f.changes.size(); ++i) {
      samples[i].push_back(tp.stats[f.changes[i]].partition_ms * 1e6);
      changes += tp.stats[f.changes[i]].partition_ms;
    }
    totals.push_back(total);
    state.SetIterationTime(changes / 1e3);
  }
  report(state, samples);
  state.counters["trace_total_ms"] = median(totals);
}

void register_all() {
  for (bool inc : {true, false})
    benchmark::RegisterBenchmark(inc ? "BM_FallingGraphUpdate/incremental" : "BM_FallingGraphUpdate/scratch",
                                 BM_FallingGraphUpdate, inc)
        ->UseManualTime()
        ->Iterations(21)
        ->Unit(benchmark::kMicrosecond);
  for (bool inc : {true, false})
    benchmark::RegisterBenchmark(inc ? "BM_FallingPlanRebuild/incremental" : "BM_FallingPlanRebuild/scratch",
                                 BM_FallingPlanRebuild, inc)
        ->Arg(2)
        ->Arg(4)
        ->Arg(8)
        ->UseManualTime()
        ->Iterations(5)
        ->Unit(benchmark::kMicrosecond);
  const std::pair<const char*, bool> methods[] = {{"metis", false}, {"sticky", false}, {"sticky", true}};
  for (const auto& [m, rep] : methods)
    benchmark::RegisterBenchmark(
        (std::string("BM_FallingPartition/") + m + (rep ? "-repartition" : "")).c_str(),
        BM_FallingPartition, m, rep)
        ->Arg(2)
        ->Arg(4)
        ->Arg(8)
        ->UseManualTime()
        ->Iterations(3)
        ->Unit(benchmark::kMillisecond);
}

}  // namespace

int main(int argc, char** argv) {
  register_all();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
