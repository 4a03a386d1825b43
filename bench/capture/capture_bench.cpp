// SPDX-License-Identifier: MIT
// Cost of recording one task through the capture API, per task and per access, against
// the uninstrumented call (Mode::kOff) in the same run.
#include <benchmark/benchmark.h>

#include "tgraph/capture/recorder.hpp"

namespace {

using tgraph::Access;
using tgraph::AccessMode;
using tgraph::capture::Mode;
using tgraph::capture::Recorder;

constexpr int kTasksPerStep = 4096;

// Records steps of kTasksPerStep tasks with `n_access` accesses each (0..8).
void record_tasks(benchmark::State& state, Mode mode) {
  const auto n_access = static_cast<int>(state.range(0));
  Recorder rec(mode);
  const auto obj = rec.object("obj");
  const auto kind = rec.kind("addForce");
  tgraph::DatumId d[8];
  for (int i = 0; i < 8; ++i) d[i] = rec.datum("d" + std::to_string(i), obj, 64);
  double sink = 0;
  auto body = [&sink] { benchmark::DoNotOptimize(sink += 1.0); };
  for (auto _ : state) {
    rec.begin_step();
    for (int t = 0; t < kTasksPerStep; ++t) {
      switch (n_access) {
        case 0: rec.task(kind, obj, {}, body); break;
        case 1: rec.task(kind, obj, {{d[0], AccessMode::R}}, body); break;
        case 4:
          rec.task(kind, obj,
                   {{d[0], AccessMode::R}, {d[1], AccessMode::R}, {d[2], AccessMode::RW}, {d[3], AccessMode::CW}},
                   body);
          break;
        default:
          rec.task(kind, obj,
                   {{d[0], AccessMode::R}, {d[1], AccessMode::R}, {d[2], AccessMode::R}, {d[3], AccessMode::R},
                    {d[4], AccessMode::RW}, {d[5], AccessMode::W}, {d[6], AccessMode::CW}, {d[7], AccessMode::CW}},
                   body);
          break;
      }
    }
    state.PauseTiming();  // end_step derives edges and keys: per step, not per task
    benchmark::DoNotOptimize(rec.end_step());
    state.ResumeTiming();
  }
  state.SetItemsProcessed(state.iterations() * kTasksPerStep);
  state.counters["ns_per_task"] = benchmark::Counter(
      static_cast<double>(state.iterations() * kTasksPerStep),
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_RecordTask_Capture(benchmark::State& s) { record_tasks(s, Mode::kCapture); }
void BM_RecordTask_Off(benchmark::State& s) { record_tasks(s, Mode::kOff); }
void BM_RecordTask_Deferred(benchmark::State& s) { record_tasks(s, Mode::kDeferred); }

// Whole-step cost including end_step (edges, stable keys), per task.
void BM_CaptureStepWithEndStep(benchmark::State& state) {
  Recorder rec(Mode::kCapture);
  const auto obj = rec.object("obj");
  const auto kind = rec.kind("addForce");
  tgraph::DatumId d[64];
  for (int i = 0; i < 64; ++i) d[i] = rec.datum("d" + std::to_string(i), obj, 64);
  for (auto _ : state) {
    rec.begin_step();
    for (int t = 0; t < kTasksPerStep; ++t)
      rec.task(kind, obj, {{d[t % 64], AccessMode::R}, {d[(t + 1) % 64], AccessMode::RW}}, [] {});
    benchmark::DoNotOptimize(rec.end_step());
  }
  state.counters["ns_per_task"] = benchmark::Counter(
      static_cast<double>(state.iterations() * kTasksPerStep),
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

}  // namespace

BENCHMARK(BM_RecordTask_Off)->Arg(0)->Arg(4);
BENCHMARK(BM_RecordTask_Capture)->Arg(0)->Arg(1)->Arg(4)->Arg(8);
BENCHMARK(BM_RecordTask_Deferred)->Arg(4);
BENCHMARK(BM_CaptureStepWithEndStep);
BENCHMARK_MAIN();
