// SPDX-License-Identifier: MIT
// The graph library: dependency extraction and the trace format, side by side in one run.
//
//   graph_bench --benchmark_filter=DeriveEdges
//
//  * DeriveEdges/tasks:N: StepGraph::derive_edges on a generated solver step (generate_step,
//    pattern domain) of about N tasks (10^3..10^7): per object a force task outside the
//    solver loop and five tasks in a CG-like loop with two global dot products, plus one
//    contact task per four objects. Counters: accesses_per_s and tasks_per_s (throughput),
//    edges_per_task. GeneratedEdges/<stencil|random>/tasks:N: the same on Task Bench's
//    shapes; IncrementalEdges/tasks:N: EdgeDeriver::derive on a step of unchanged structure
//    (every datum's edges carried over); Metrics/tasks:N: compute_metrics;
//    GeneratedTrace/<encode|decode>/tasks:N: a one-step trace of the solver step (up to 10^6).
//  * TraceEncode / TraceDecode/<scene>/<reuse|full>: encode_trace and read_trace_bytes (edges
//    derived, as every reader does) in memory, on a trace captured from a scene, with steps
//    of repeated structure stored as reference frames (reuse) or every step as a full frame
//    (WriteOptions::reuse_structure = false). Counters: bytes_per_second (MB/s of trace),
//    items_per_second (tasks/s), bytes_per_task.
//  * TraceWriteFile / TraceReadFile/<scene>: write_trace (encode, write, fsync, rename) and
//    read_trace from a file in the temporary directory.
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "bench_main.hpp"
#include "tgraph/capture/recorder.hpp"
#include "tgraph/graph/generate.hpp"
#include "tgraph/graph/incremental.hpp"
#include "tgraph/graph/metrics.hpp"
#include "tgraph/graph/trace.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/samples/scene.hpp"

namespace {

using namespace tgraph;
using bench::Size;

/// A generated step of about `tasks` tasks (edges not derived), kept while the same pattern
/// and size are asked for: Google Benchmark calls a benchmark function several times per
/// repetition. One step at a time (a 10^7-task step holds a few GB).
StepGraph& generated(Pattern pattern, std::int64_t tasks) {
  static std::pair<Pattern, std::int64_t> key{Pattern::kTrivial, 0};
  static StepGraph cached;
  if (key != std::pair{pattern, tasks}) {
    cached = {};
    cached = generate_step({.tasks = static_cast<std::uint64_t>(tasks), .pattern = pattern});
    key = {pattern, tasks};
  }
  return cached;
}

/// Throughput counters of one pass over a step per iteration.
void step_counters(benchmark::State& state, const StepGraph& g) {
  const auto it = static_cast<double>(state.iterations());
  const auto tasks = static_cast<double>(g.tasks.size());
  state.counters["tasks"] = tasks;
  state.counters["accesses_per_s"] =
      benchmark::Counter(it * static_cast<double>(g.accesses.size()), benchmark::Counter::kIsRate);
  state.counters["tasks_per_s"] = benchmark::Counter(it * tasks, benchmark::Counter::kIsRate);
  state.counters["edges_per_task"] =
      static_cast<double>(g.edges.size() + g.carried_edges.size()) / tasks;
}

void derive_edges(benchmark::State& state, Pattern pattern) {
  StepGraph& g = generated(pattern, state.range(0));
  for (auto _ : state) {
    g.derive_edges();
    benchmark::DoNotOptimize(g.edges.data());
    benchmark::ClobberMemory();
  }
  step_counters(state, g);
}

// The scaled solver step (pattern domain): the case the engine produces.
void BM_DeriveEdges(benchmark::State& state) { derive_edges(state, Pattern::kDomain); }

// Task Bench's stencil and random shapes.
void BM_GeneratedEdges(benchmark::State& state, Pattern pattern) { derive_edges(state, pattern); }

// EdgeDeriver::derive on a step of the same structure as the previous one (every datum's
// edges carried over, renumbered by stable key), the solver step.
void BM_IncrementalEdges(benchmark::State& state) {
  StepGraph& g = generated(Pattern::kDomain, state.range(0));
  g.derive_edges();
  EdgeDeriver deriver;
  deriver.seed(g);
  StepGraph next = g;
  for (auto _ : state) {
    const EdgeUpdate u = deriver.derive(next);
    benchmark::DoNotOptimize(u.edges);
  }
  step_counters(state, next);
}

// encode_trace and read_trace_bytes (edges derived) of a one-step trace of the solver step.
void BM_GeneratedTrace(benchmark::State& state, bool decode) {
  Trace t;
  t.steps.push_back(std::move(generated(Pattern::kDomain, state.range(0))));
  t.steps[0].derive_edges();
  std::size_t bytes = 0;
  if (decode) {
    const std::vector<std::uint8_t> b = encode_trace(t);
    bytes = b.size();
    for (auto _ : state) {
      const Trace back = read_trace_bytes(b, "generated");
      benchmark::DoNotOptimize(back.steps.data());
    }
  } else {
    for (auto _ : state) {
      const std::vector<std::uint8_t> b = encode_trace(t);
      bytes = b.size();
      benchmark::DoNotOptimize(b.data());
    }
  }
  step_counters(state, t.steps[0]);
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(bytes));
  state.counters["bytes_per_task"] =
      static_cast<double>(bytes) / static_cast<double>(t.steps[0].tasks.size());
  generated(Pattern::kDomain, state.range(0)) = std::move(t.steps[0]);  // back to the cache
}

// compute_metrics (work, span with the loop unrolled, per kind), the solver step.
void BM_Metrics(benchmark::State& state) {
  StepGraph& g = generated(Pattern::kDomain, state.range(0));
  g.derive_edges();
  for (auto _ : state) {
    const Metrics m = compute_metrics(g);
    benchmark::DoNotOptimize(m.span_ns);
  }
  step_counters(state, g);
}

// ---- traces ---------------------------------------------------------------------------

int g_steps_bars64 = 10, g_steps_falling = 100;

/// The first `steps` steps of a scene, captured once per process.
const Trace& trace_of(const std::string& scene_name) {
  static std::map<std::string, Trace> cache;
  auto it = cache.find(scene_name);
  if (it != cache.end()) return it->second;
  Trace t;
  auto scene = samples::make_scene(scene_name);
  t.header.scene = scene_name;
  t.header.engine = "graph_bench";
  capture::Recorder rec(capture::Mode::kCapture);
  rec.set_derive_edges(false);
  const int steps = scene_name == "bars64" ? g_steps_bars64 : g_steps_falling;
  for (int s = 0; s < steps; ++s) {
    scene->step(rec);
    t.steps.push_back(rec.end_step());
  }
  return cache.emplace(scene_name, std::move(t)).first->second;
}

std::uint64_t tasks_of(const Trace& t) {
  std::uint64_t n = 0;
  for (const StepGraph& g : t.steps) n += g.tasks.size();
  return n;
}

void trace_counters(benchmark::State& state, const Trace& t, std::size_t bytes) {
  const auto it = static_cast<std::int64_t>(state.iterations());
  state.SetBytesProcessed(it * static_cast<std::int64_t>(bytes));
  state.SetItemsProcessed(it * static_cast<std::int64_t>(tasks_of(t)));
  state.counters["bytes_per_task"] = static_cast<double>(bytes) / static_cast<double>(tasks_of(t));
  state.counters["steps"] = static_cast<double>(t.steps.size());
}

void BM_TraceEncode(benchmark::State& state, const std::string& scene, bool reuse) {
  const Trace& t = trace_of(scene);
  std::size_t bytes = 0;
  for (auto _ : state) {
    const std::vector<std::uint8_t> b = encode_trace(t, {.reuse_structure = reuse});
    bytes = b.size();
    benchmark::DoNotOptimize(b.data());
  }
  trace_counters(state, t, bytes);
}

void BM_TraceDecode(benchmark::State& state, const std::string& scene, bool reuse) {
  const Trace& t = trace_of(scene);
  const std::vector<std::uint8_t> bytes = encode_trace(t, {.reuse_structure = reuse});
  for (auto _ : state) {
    const Trace back = read_trace_bytes(bytes, scene);
    benchmark::DoNotOptimize(back.steps.data());
  }
  trace_counters(state, t, bytes.size());
}

std::string temp_trace(const std::string& scene) {
  return (std::filesystem::temp_directory_path() /
          ("tgraph-graph-bench-" + std::to_string(::getpid()) + "-" + scene + ".tgt"))
      .string();
}

void BM_TraceWriteFile(benchmark::State& state, const std::string& scene) {
  const Trace& t = trace_of(scene);
  const std::string path = temp_trace(scene);
  for (auto _ : state) write_trace(path, t);
  trace_counters(state, t, std::filesystem::file_size(path));
  std::filesystem::remove(path);
}

void BM_TraceReadFile(benchmark::State& state, const std::string& scene) {
  const Trace& t = trace_of(scene);
  const std::string path = temp_trace(scene);
  write_trace(path, t);
  for (auto _ : state) {
    const Trace back = read_trace(path);
    benchmark::DoNotOptimize(back.steps.data());
  }
  trace_counters(state, t, std::filesystem::file_size(path));
  std::filesystem::remove(path);
}

void register_all(Size size) {
  g_steps_bars64 = bench::by_size(size, 2, 5, 10);
  g_steps_falling = bench::by_size(size, 50, 100, 100);
  // 10^7 only in full runs (a few GB of memory and seconds per pass).
  const auto sizes = bench::by_size<std::vector<std::int64_t>>(
      size, {1000}, {1000, 100000}, {1000, 10000, 100000, 1000000, 10000000});
  const auto scaled = [&](benchmark::internal::Benchmark* b) {
    b->ArgName("tasks")->Unit(benchmark::kMicrosecond);
    for (const std::int64_t n : sizes) b->Arg(n);
    bench::timed(b, size, 0.5);
  };
  scaled(benchmark::RegisterBenchmark("BM_DeriveEdges", BM_DeriveEdges));
  for (const Pattern p : {Pattern::kStencil, Pattern::kRandom})
    scaled(benchmark::RegisterBenchmark(
        ("BM_GeneratedEdges/" + std::string(to_string(p))).c_str(), BM_GeneratedEdges, p));
  scaled(benchmark::RegisterBenchmark("BM_IncrementalEdges", BM_IncrementalEdges));
  scaled(benchmark::RegisterBenchmark("BM_Metrics", BM_Metrics));
  // Encoded and decoded copies beside the step: up to 10^6 tasks.
  for (const bool decode : {false, true}) {
    auto* b = benchmark::RegisterBenchmark(decode ? "BM_GeneratedTrace/decode" : "BM_GeneratedTrace/encode",
                                           BM_GeneratedTrace, decode)
                  ->ArgName("tasks")
                  ->Unit(benchmark::kMillisecond);
    for (const std::int64_t n : sizes)
      if (n <= 1000000) b->Arg(n);
    bench::timed(b, size, 0.5);
  }
  for (const std::string scene : {"bars64", "falling"}) {
    for (const bool reuse : {true, false}) {
      const std::string suffix = scene + (reuse ? "/reuse" : "/full");
      bench::timed(benchmark::RegisterBenchmark(("BM_TraceEncode/" + suffix).c_str(),
                                                BM_TraceEncode, scene, reuse)
                       ->Unit(benchmark::kMillisecond),
                   size, 0.3);
      bench::timed(benchmark::RegisterBenchmark(("BM_TraceDecode/" + suffix).c_str(),
                                                BM_TraceDecode, scene, reuse)
                       ->Unit(benchmark::kMillisecond),
                   size, 0.3);
    }
    bench::timed(benchmark::RegisterBenchmark(("BM_TraceWriteFile/" + scene).c_str(),
                                              BM_TraceWriteFile, scene)
                     ->Unit(benchmark::kMillisecond)
                     ->UseRealTime(),
                 size, 0.3);
    bench::timed(
        benchmark::RegisterBenchmark(("BM_TraceReadFile/" + scene).c_str(), BM_TraceReadFile, scene)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime(),
        size, 0.3);
  }
}

}  // namespace

int main(int argc, char** argv) { return tgraph::bench::run_main(argc, argv, register_all); }
