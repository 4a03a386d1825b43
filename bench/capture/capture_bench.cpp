// SPDX-License-Identifier: MIT
// Cost of recording one task through the capture API, per task and per access, against
// the uninstrumented call (Mode::kOff) in the same run.
//
//  * RecordTask_<mode>/accesses:N: Recorder::task with N accesses (0, 1, 4, 8) and an almost
//    empty body, end_step() outside the timing. Counter: ns_per_task; the cost per access is
//    the slope over N (docs/benchmarks.md, Ratios).
//  * CaptureStepWithEndStep: the same plus end_step() (edges, stable keys) per 4096 tasks.
#include <string>
#include <vector>

#include "bench_main.hpp"
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
  for (int i = 0; i < 8; ++i) d[i] = rec.datum(std::string("d").append(std::to_string(i)), obj, 64);
  double sink = 0;
  auto body = [&sink] { benchmark::DoNotOptimize(sink += 1.0); };
  for (auto _ : state) {
    rec.begin_step();
    for (int t = 0; t < kTasksPerStep; ++t) {
      switch (n_access) {
        case 0:
          rec.task(kind, obj, {}, body);
          break;
        case 1:
          rec.task(kind, obj, {{d[0], AccessMode::R}}, body);
          break;
        case 4:
          rec.task(kind, obj,
                   {{d[0], AccessMode::R},
                    {d[1], AccessMode::R},
                    {d[2], AccessMode::RW},
                    {d[3], AccessMode::CW}},
                   body);
          break;
        default:
          rec.task(kind, obj,
                   {{d[0], AccessMode::R},
                    {d[1], AccessMode::R},
                    {d[2], AccessMode::R},
                    {d[3], AccessMode::R},
                    {d[4], AccessMode::RW},
                    {d[5], AccessMode::W},
                    {d[6], AccessMode::CW},
                    {d[7], AccessMode::CW}},
                   body);
          break;
      }
    }
    state.PauseTiming();  // end_step derives edges and keys: per step, not per task
    benchmark::DoNotOptimize(rec.end_step());
    state.ResumeTiming();
  }
  state.SetItemsProcessed(state.iterations() * kTasksPerStep);
  state.counters["ns_per_task"] =
      benchmark::Counter(static_cast<double>(state.iterations() * kTasksPerStep),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  if (n_access > 0)
    state.counters["ns_per_access"] =
        benchmark::Counter(static_cast<double>(state.iterations() * kTasksPerStep * n_access),
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
  for (int i = 0; i < 64; ++i)
    d[i] = rec.datum(std::string("d").append(std::to_string(i)), obj, 64);
  for (auto _ : state) {
    rec.begin_step();
    for (int t = 0; t < kTasksPerStep; ++t)
      rec.task(kind, obj, {{d[t % 64], AccessMode::R}, {d[(t + 1) % 64], AccessMode::RW}}, [] {});
    benchmark::DoNotOptimize(rec.end_step());
  }
  state.counters["ns_per_task"] =
      benchmark::Counter(static_cast<double>(state.iterations() * kTasksPerStep),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void register_all(tgraph::bench::Size size) {
  using tgraph::bench::timed;
  const bool smoke = size == tgraph::bench::Size::kSmoke;
  auto* off =
      benchmark::RegisterBenchmark("BM_RecordTask_Off", BM_RecordTask_Off)->ArgName("accesses");
  auto* cap = benchmark::RegisterBenchmark("BM_RecordTask_Capture", BM_RecordTask_Capture)
                  ->ArgName("accesses");
  for (int n : smoke ? std::vector<int>{4} : std::vector<int>{0, 4}) off->Arg(n);
  for (int n : smoke ? std::vector<int>{4} : std::vector<int>{0, 1, 4, 8}) cap->Arg(n);
  timed(off, size, 0.2);
  timed(cap, size, 0.2);
  timed(benchmark::RegisterBenchmark("BM_RecordTask_Deferred", BM_RecordTask_Deferred)
            ->ArgName("accesses")
            ->Arg(4),
        size, 0.2);
  timed(benchmark::RegisterBenchmark("BM_CaptureStepWithEndStep", BM_CaptureStepWithEndStep), size,
        0.2);
}

}  // namespace

int main(int argc, char** argv) { return tgraph::bench::run_main(argc, argv, register_all); }
