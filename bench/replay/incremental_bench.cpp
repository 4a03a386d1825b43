// SPDX-License-Identifier: MIT
// What a contact change costs on the dynamic scene `falling` (300 steps, captured once):
// the graph update (edges derived incrementally from the previous step, and from scratch),
// the partition executor's plan rebuild (incremental, and from scratch) at K = 2, 4, 8 on
// sticky's assignments, and the partitioning time of METIS and of sticky with each
// `--sticky-fallback` (sticky: the default, refine; sticky-fresh; sticky-repartition,
// migration cost 1) on the same steps; then the whole
// rebuild after a contact change against the time of a simulation step (paper: graph
// update ~ one 30 ms step):
//  * FallingRebuild/incremental/k:K: what a live run does at a change: edges from the
//    previous step's (EdgeDeriver), sticky given the previous step's sticky assignment,
//    the executor's incremental plan update (lowering + per-processor programs);
//    FallingRebuild/scratch/k:K: derive_edges, METIS afresh, the plan from scratch.
//    Counters: median_us, max_us and the parts' medians edges_us, partition_us, plan_us.
//  * FallingStep: one uninstrumented step (Mode::kOff) of the same scene; its time is the
//    median step of the run; counters: median_ms (all steps), changes_median_ms (the steps
//    whose structure changed), mean_ms.
//
//   incremental_bench --benchmark_filter=Falling
//
// Each benchmark iteration goes over every step whose structure differs from the previous
// step's (a contact change) and times that step alone; the counters are, over those
// steps, the median (median_us) and the maximum (max_us) of each step's median over the
// iterations; the benchmark's own time is the sum over the changes. Plan rebuilds are
// timed by the executor (ExecStepStats::rebuild_ns: the per-processor programs, lowering
// excluded; lowering_us is the lowering's median), on a fresh executor that first built
// the previous step's plan. Graph updates alternate between the previous step and the
// changed one, so that each derivation starts from the other step.
#include <algorithm>
#include <chrono>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "bench_main.hpp"
#include "tgraph/capture/recorder.hpp"
#include "tgraph/graph/incremental.hpp"
#include "tgraph/graph/median.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/partition/strategy.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/synthetic.hpp"
#include "tgraph/samples/scene.hpp"

namespace {

using tgraph::median;
using tgraph::StepGraph;

struct Falling {
  tgraph::Trace trace;
  std::vector<std::size_t> changes;  // steps whose structure differs from the previous one
};

int g_falling_steps = 0;  // 0: the scene's default (300)

const Falling& falling() {
  static const Falling f = [] {
    Falling r;
    auto scene = tgraph::samples::make_scene("falling");
    tgraph::capture::Recorder rec(tgraph::capture::Mode::kCapture);
    const int steps = g_falling_steps > 0 ? g_falling_steps : scene->default_steps();
    for (int s = 0; s < steps; ++s) {
      scene->step(rec);
      r.trace.steps.push_back(rec.end_step());
    }
    for (std::size_t s = 1; s < r.trace.steps.size(); ++s)
      if (!r.trace.steps[s].same_structure(r.trace.steps[s - 1])) r.changes.push_back(s);
    return r;
  }();
  return f;
}

// Counters from per-change samples (ns): median and max of the per-change medians.
void report(benchmark::State& state, const std::vector<std::vector<double>>& samples,
            const std::string& prefix = "") {
  std::vector<double> med;
  for (const auto& s : samples) med.push_back(median(s));
  state.counters[prefix + "median_us"] = median(med) / 1e3;
  state.counters[prefix + "max_us"] =
      med.empty() ? 0 : *std::max_element(med.begin(), med.end()) / 1e3;
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
    state.counters["rederived_data_pct"] =
        100.0 * static_cast<double>(rederived) / static_cast<double>(accessed);
}

const tgraph::partition::TracePartition& sticky(std::uint32_t k) {
  static std::map<std::uint32_t, tgraph::partition::TracePartition> cache;
  auto it = cache.find(k);
  if (it == cache.end())
    it = cache.emplace(k, tgraph::partition::partition_trace(falling().trace, "sticky", k)).first;
  return it->second;
}

void BM_FallingPlanRebuild(benchmark::State& state, bool incremental) {
  const Falling& f = falling();
  const auto k = static_cast<std::uint32_t>(state.range(0));
  const tgraph::partition::TracePartition& tp = sticky(k);
  tgraph::replay::ExecOptions o;
  o.threads = k;
  o.partition.serial = true;  // the programs are built the same way; the step runs on this thread
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
      const tgraph::replay::ExecStepStats st =
          ex->run_step(f.trace.steps[s], &tp.assignment.steps[s], w);
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

void BM_FallingPartition(benchmark::State& state, const char* method,
                         std::optional<tgraph::partition::StickyFallback> fallback) {
  const Falling& f = falling();
  const auto k = static_cast<std::uint32_t>(state.range(0));
  tgraph::partition::Options options;
  if (fallback) options.sticky_fallback = *fallback;
  std::vector<std::vector<double>> samples(f.changes.size());
  std::vector<double> totals;
  for (auto _ : state) {
    const tgraph::partition::TracePartition tp =
        tgraph::partition::partition_trace(f.trace, method, k, options);
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

using Clock = std::chrono::steady_clock;

double ns_since(Clock::time_point t0) {
  return static_cast<double>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - t0).count());
}

void BM_FallingRebuild(benchmark::State& state, bool incremental) {
  const Falling& f = falling();
  const auto k = static_cast<std::uint32_t>(state.range(0));
  const tgraph::partition::TracePartition& tp = sticky(k);
  auto strategy = tgraph::partition::make_strategy(incremental ? "sticky" : "metis");
  tgraph::replay::ExecOptions o;
  o.threads = k;
  o.partition.serial = true;  // the programs are built the same way; the step runs on this thread
  o.pin = false;
  o.incremental_plans = incremental;
  tgraph::replay::SyntheticWorkload w({.cost_scale = 0.0});
  const std::size_t n = f.changes.size();
  std::vector<std::vector<double>> total(n), edges(n), part(n), plan(n);
  for (auto _ : state) {
    double sum = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t s = f.changes[i];
      const StepGraph& prev = f.trace.steps[s - 1];
      StepGraph g = f.trace.steps[s];
      tgraph::EdgeDeriver deriver;
      deriver.seed(prev);
      auto ex = tgraph::replay::make_executor(tgraph::replay::Policy::kPartition, o);
      w.set_step(prev);
      ex->run_step(prev, &tp.assignment.steps[s - 1], w);
      // The timed part: edges, partition, plan, one after the other as in a live run.
      auto t0 = Clock::now();
      if (incremental) {
        deriver.derive(g);
      } else {
        g.derive_edges();
      }
      const double e = ns_since(t0);
      t0 = Clock::now();
      const tgraph::partition::Previous previous =
          incremental ? tgraph::partition::Previous{&prev, &tp.assignment.steps[s - 1]}
                      : tgraph::partition::Previous{};
      const tgraph::partition::Result r = strategy->partition(g, k, previous, {});
      const double p = ns_since(t0);
      w.set_step(g);
      const tgraph::replay::ExecStepStats st = ex->run_step(g, &r.assignment, w);
      const auto b = static_cast<double>(st.build_ns);
      edges[i].push_back(e);
      part[i].push_back(p);
      plan[i].push_back(b);
      total[i].push_back(e + p + b);
      sum += e + p + b;
    }
    state.SetIterationTime(sum / 1e9 / static_cast<double>(n));
  }
  report(state, total);
  report(state, edges, "edges_");
  report(state, part, "partition_");
  report(state, plan, "plan_");
}

void BM_FallingStep(benchmark::State& state) {
  const Falling& f = falling();
  std::vector<double> all, at_changes;
  for (auto _ : state) {
    auto scene = tgraph::samples::make_scene("falling");
    tgraph::capture::Recorder rec(tgraph::capture::Mode::kOff);
    std::vector<double> steps;
    for (std::size_t s = 0; s < f.trace.steps.size(); ++s) {
      const auto t0 = Clock::now();
      scene->step(rec);
      rec.end_step();
      steps.push_back(ns_since(t0));
    }
    for (const std::size_t c : f.changes) at_changes.push_back(steps[c]);
    all.insert(all.end(), steps.begin(), steps.end());
    state.SetIterationTime(median(steps) / 1e9);
  }
  double mean = 0;
  for (const double v : all) mean += v;
  state.counters["median_ms"] = median(all) / 1e6;
  state.counters["changes_median_ms"] = median(at_changes) / 1e6;
  state.counters["mean_ms"] = all.empty() ? 0 : mean / static_cast<double>(all.size()) / 1e6;
  state.counters["steps"] = static_cast<double>(f.trace.steps.size());
}

void register_all(tgraph::bench::Size size) {
  using tgraph::bench::by_size;
  g_falling_steps = by_size(size, 50, 150, 0);
  const std::vector<int> ks = by_size<std::vector<int>>(size, {2}, {2, 8}, {2, 4, 8});
  const auto with_ks = [&](benchmark::internal::Benchmark* b) {
    b->ArgName("k");
    for (const int k : ks) b->Arg(k);
    return b;
  };
  for (bool inc : {true, false})
    benchmark::RegisterBenchmark(
        inc ? "BM_FallingGraphUpdate/incremental" : "BM_FallingGraphUpdate/scratch",
        BM_FallingGraphUpdate, inc)
        ->UseManualTime()
        ->Iterations(by_size(size, 1, 7, 21))
        ->Unit(benchmark::kMicrosecond);
  for (bool inc : {true, false})
    with_ks(benchmark::RegisterBenchmark(
                inc ? "BM_FallingPlanRebuild/incremental" : "BM_FallingPlanRebuild/scratch",
                BM_FallingPlanRebuild, inc))
        ->UseManualTime()
        ->Iterations(by_size(size, 1, 2, 5))
        ->Unit(benchmark::kMicrosecond);
  using tgraph::partition::StickyFallback;
  const std::tuple<const char*, const char*, std::optional<StickyFallback>> methods[] = {
      {"metis", "metis", std::nullopt},
      {"sticky", "sticky", std::nullopt},
      {"sticky-fresh", "sticky", StickyFallback::kFresh},
      {"sticky-repartition", "sticky", StickyFallback::kRepartition}};
  for (const auto& [name, m, fallback] : methods)
    with_ks(benchmark::RegisterBenchmark((std::string("BM_FallingPartition/") + name).c_str(),
                                         BM_FallingPartition, m, fallback))
        ->UseManualTime()
        ->Iterations(by_size(size, 1, 1, 2))
        ->Unit(benchmark::kMillisecond);
  for (bool inc : {true, false})
    with_ks(benchmark::RegisterBenchmark(
                inc ? "BM_FallingRebuild/incremental" : "BM_FallingRebuild/scratch",
                BM_FallingRebuild, inc))
        ->UseManualTime()
        ->Iterations(by_size(size, 1, 2, 5))
        ->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark("BM_FallingStep", BM_FallingStep)
      ->UseManualTime()
      ->Iterations(1)
      ->Unit(benchmark::kMillisecond);
}

}  // namespace

int main(int argc, char** argv) { return tgraph::bench::run_main(argc, argv, register_all); }
