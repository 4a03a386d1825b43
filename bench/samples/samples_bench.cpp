// SPDX-License-Identifier: MIT
// The instrumented engine: cost of a time step uninstrumented (Mode::kOff) and captured
// (Mode::kCapture, graph built with its edges), side by side.
//
//   samples_bench --benchmark_filter=Overhead
//
// BM_CaptureOverhead runs two copies of the scene in lockstep, one uninstrumented and one
// captured step per iteration (in alternating order), so both see the same machine load and, the physics
// being deterministic and identical in both modes, the same CG iteration counts. Counters:
// off_ms and capture_ms (mean step time), overhead_pct (100 (capture / off - 1) from the
// sums) and median_overhead_pct (median of the per-step ratios, robust to preemptions).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include "tgraph/capture/recorder.hpp"
#include "tgraph/samples/scene.hpp"

namespace {

using tgraph::capture::Mode;
using tgraph::capture::Recorder;
using Clock = std::chrono::steady_clock;

const char* const kScenes[] = {"fig2", "bars64", "falling", "cloth128", "torso"};

void BM_Step(benchmark::State& state, const char* scene_name, Mode mode) {
  auto scene = tgraph::samples::make_scene(scene_name);
  Recorder rec(mode);
  std::uint64_t tasks = 0, cg = 0;
  for (auto _ : state) {
    scene->step(rec);
    const tgraph::StepGraph g = rec.end_step();
    tasks += g.tasks.size();
    cg += scene->last_stats().cg_iterations;
    benchmark::DoNotOptimize(g.tasks.data());
  }
  state.counters["tasks"] = benchmark::Counter(static_cast<double>(tasks), benchmark::Counter::kAvgIterations);
  state.counters["cg_iterations"] = benchmark::Counter(static_cast<double>(cg), benchmark::Counter::kAvgIterations);
}

void BM_CaptureOverhead(benchmark::State& state, const char* scene_name) {
  auto off_scene = tgraph::samples::make_scene(scene_name);
  auto cap_scene = tgraph::samples::make_scene(scene_name);
  Recorder off(Mode::kOff);
  Recorder cap(Mode::kCapture);
  cap.set_derive_edges(false);  // as `tgraph capture`: the trace stores no edges
  double off_s = 0.0, cap_s = 0.0;
  std::vector<double> ratios;
  auto step_off = [&] {
    const auto t0 = Clock::now();
    off_scene->step(off);
    off.end_step();
    return std::chrono::duration<double>(Clock::now() - t0).count();
  };
  auto step_cap = [&] {
    const auto t0 = Clock::now();
    cap_scene->step(cap);
    const tgraph::StepGraph g = cap.end_step();
    benchmark::DoNotOptimize(g.tasks.data());
    return std::chrono::duration<double>(Clock::now() - t0).count();
  };
  bool off_first = true;
  for (auto _ : state) {
    // Alternate which mode runs first, so neither always finds the caches warm.
    double a = 0.0, b = 0.0;
    if (off_first) {
      a = step_off();
      b = step_cap();
    } else {
      b = step_cap();
      a = step_off();
    }
    off_first = !off_first;
    off_s += a;
    cap_s += b;
    ratios.push_back(b / a);
  }
  const double n = static_cast<double>(state.iterations());
  std::sort(ratios.begin(), ratios.end());
  state.counters["off_ms"] = 1000.0 * off_s / n;
  state.counters["capture_ms"] = 1000.0 * cap_s / n;
  state.counters["overhead_pct"] = 100.0 * (cap_s / off_s - 1.0);
  state.counters["median_overhead_pct"] = ratios.empty() ? 0.0 : 100.0 * (ratios[ratios.size() / 2] - 1.0);
}

int register_all() {
  for (const char* s : kScenes) {
    benchmark::RegisterBenchmark((std::string("BM_Step/") + s + "/off").c_str(), BM_Step, s, Mode::kOff)
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark((std::string("BM_Step/") + s + "/capture").c_str(), BM_Step, s, Mode::kCapture)
        ->Unit(benchmark::kMillisecond);
  }
  benchmark::RegisterBenchmark("BM_CaptureOverhead/bars64", BM_CaptureOverhead, "bars64")
      ->Unit(benchmark::kMillisecond)
      ->Iterations(60);
  return 0;
}

const int kRegistered = register_all();

}  // namespace

BENCHMARK_MAIN();
