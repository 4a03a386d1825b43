// SPDX-License-Identifier: MIT
// The instrumented engine: cost of a time step uninstrumented (Mode::kOff) and captured
// (Mode::kCapture), side by side. BM_Step/<scene>/<mode>: one scene's step time alone.
//
//   samples_bench --benchmark_filter=Overhead
//
// BM_CaptureOverhead/<scene> runs three copies of the scene in lockstep: uninstrumented
// (Mode::kOff), captured as `tgraph capture` does (steps recorded, edges left to the trace
// reader) and captured with the edges derived by end_step() (as a live run or
// `tgraph run` needs them); one step of each per iteration, in rotating order, so all three
// see the same machine load and, the physics being deterministic and identical in every
// mode, the same CG iteration counts. Counters: off_ms, capture_ms and capture_edges_ms
// (mean step time), overhead_pct and edges_overhead_pct (100 (mode / off - 1) from the
// sums), median_overhead_pct and median_edges_overhead_pct (median of the per-step ratios,
// robust to preemptions).
#include <algorithm>
#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "bench_main.hpp"
#include "tgraph/capture/recorder.hpp"
#include "tgraph/samples/scene.hpp"

namespace {

using tgraph::capture::Mode;
using tgraph::capture::Recorder;
using Clock = std::chrono::steady_clock;

const char* const kScenes[] = {"bars64", "falling", "cloth128", "torso"};

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
  state.counters["tasks"] =
      benchmark::Counter(static_cast<double>(tasks), benchmark::Counter::kAvgIterations);
  state.counters["cg_iterations"] =
      benchmark::Counter(static_cast<double>(cg), benchmark::Counter::kAvgIterations);
}

double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : (v[v.size() / 2 - 1] + v[v.size() / 2]) / 2;
}

void BM_CaptureOverhead(benchmark::State& state, const char* scene_name) {
  struct Twin {
    Twin(const char* name, Mode mode) : scene(tgraph::samples::make_scene(name)), rec(mode) {}
    std::unique_ptr<tgraph::samples::Scene> scene;
    Recorder rec;
    double total_s = 0.0;
    double last_s = 0.0;
  };
  Twin twins[3] = {
      {scene_name, Mode::kOff}, {scene_name, Mode::kCapture}, {scene_name, Mode::kCapture}};
  twins[1].rec.set_derive_edges(false);  // as `tgraph capture`: the trace stores no edges
  std::vector<double> ratios, edge_ratios;
  std::size_t first = 0;
  for (auto _ : state) {
    // Rotate which mode runs first, so that none always finds the caches warm.
    for (std::size_t i = 0; i < 3; ++i) {
      Twin& t = twins[(first + i) % 3];
      const auto t0 = Clock::now();
      t.scene->step(t.rec);
      const tgraph::StepGraph g = t.rec.end_step();
      t.last_s = std::chrono::duration<double>(Clock::now() - t0).count();
      t.total_s += t.last_s;
      benchmark::DoNotOptimize(g.tasks.data());
    }
    first = (first + 1) % 3;
    ratios.push_back(twins[1].last_s / twins[0].last_s);
    edge_ratios.push_back(twins[2].last_s / twins[0].last_s);
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["off_ms"] = 1000.0 * twins[0].total_s / n;
  state.counters["capture_ms"] = 1000.0 * twins[1].total_s / n;
  state.counters["capture_edges_ms"] = 1000.0 * twins[2].total_s / n;
  state.counters["overhead_pct"] = 100.0 * (twins[1].total_s / twins[0].total_s - 1.0);
  state.counters["edges_overhead_pct"] = 100.0 * (twins[2].total_s / twins[0].total_s - 1.0);
  state.counters["median_overhead_pct"] = 100.0 * (median_of(ratios) - 1.0);
  state.counters["median_edges_overhead_pct"] = 100.0 * (median_of(edge_ratios) - 1.0);
}

void register_all(tgraph::bench::Size size) {
  using tgraph::bench::by_size;
  for (const char* s : kScenes) {
    for (const Mode m : {Mode::kOff, Mode::kCapture})
      tgraph::bench::timed(
          benchmark::RegisterBenchmark(
              (std::string("BM_Step/") + s + "/" + std::string(to_string(m))).c_str(), BM_Step, s,
              m)
              ->Unit(benchmark::kMillisecond),
          size, 0.3);
  }
  for (const char* s : {"bars64", "cloth128", "falling"}) {
    const bool small = std::string(s) == "falling";  // a few ms per step
    benchmark::RegisterBenchmark((std::string("BM_CaptureOverhead/") + s).c_str(),
                                 BM_CaptureOverhead, s)
        ->Unit(benchmark::kMillisecond)
        ->Iterations(by_size(size, 2, small ? 40 : 8, small ? 100 : 20));
  }
}

}  // namespace

int main(int argc, char** argv) { return tgraph::bench::run_main(argc, argv, register_all); }
