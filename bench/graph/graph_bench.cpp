// SPDX-License-Identifier: MIT
// The graph library: dependency extraction and the trace format, side by side in one run.
//
//   graph_bench --benchmark_filter=DeriveEdges
//
//  * DeriveEdges/tasks:N: StepGraph::derive_edges on a synthetic physics-like step of about
//    N tasks (10^3..10^6): per object a force task outside the solver loop and five tasks
//    in a CG-like loop with two global dot products, plus one contact task per four objects.
//    Counters: accesses_per_s and tasks_per_s (throughput), edges_per_task.
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
#include "tgraph/graph/trace.hpp"
#include "tgraph/graph/trace_io.hpp"
#include "tgraph/samples/scene.hpp"

namespace {

using namespace tgraph;
using bench::Size;

/// About `tasks` tasks: objects * 6 + objects / 4 contacts + 3 shared tasks. Each global sum
/// (CW by every object) has one reader, whose scalar the objects then read: edges stay
/// linear in the tasks (a sum read by every object directly gives writers x readers edges).
StepGraph physics_like(std::uint32_t tasks) {
  const std::uint32_t objects = std::max<std::uint32_t>(1, tasks * 4 / 25);
  StepGraph g;
  const KindId kf = g.intern_kind("addForce"), kc = g.intern_kind("contact"),
               kd = g.intern_kind("addDForce"), kpq = g.intern_kind("dotPQ"),
               ks = g.intern_kind("cgScalars"), ku = g.intern_kind("cgUpdate"),
               krr = g.intern_kind("dotRR"), kres = g.intern_kind("residual"),
               kdir = g.intern_kind("cgDirection"), kb = g.intern_kind("loop.break");
  std::vector<DatumId> x, f, p, q, r;
  g.objects.reserve(objects);
  g.data.reserve(objects * 5 + 5);
  for (std::uint32_t o = 0; o < objects; ++o) {
    const std::string name = "body" + std::to_string(o);
    g.objects.push_back({name});
    for (auto* v : {&x, &f, &p, &q, &r}) {
      v->push_back(static_cast<DatumId>(g.data.size()));
      g.data.push_back({name + ".v" + std::to_string(v->size()), o, 6144});
    }
  }
  const auto pq = static_cast<DatumId>(g.data.size());
  const DatumId alpha = pq + 1, rr = pq + 2, beta = pq + 3, cond = pq + 4;
  for (const char* n : {"pq", "alpha", "rr", "beta", "cond"}) g.data.push_back({n, kNoObject, 8});
  StableKey key = 1;
  auto add = [&](KindId k, ObjectId o, std::initializer_list<Access> acc, bool in_loop) {
    const std::vector<Access> v(acc);
    const TaskId t = g.add_task(k, o, v, 1000, key++);
    if (in_loop) g.tasks[t].loop = 0;
  };
  for (std::uint32_t o = 0; o < objects; ++o)
    add(kf, o, {{x[o], AccessMode::R}, {f[o], AccessMode::CW}}, false);
  for (std::uint32_t o = 0; o + 1 < objects; o += 4)
    add(kc, o,
        {{x[o], AccessMode::R},
         {x[o + 1], AccessMode::R},
         {f[o], AccessMode::CW},
         {f[o + 1], AccessMode::CW}},
        false);
  Loop loop;
  loop.condition = cond;
  loop.first = static_cast<TaskId>(g.tasks.size());
  loop.iterations = 25;
  loop.max_iterations = 200;
  for (std::uint32_t o = 0; o < objects; ++o)
    add(kd, o, {{f[o], AccessMode::R}, {p[o], AccessMode::R}, {q[o], AccessMode::W}}, true);
  for (std::uint32_t o = 0; o < objects; ++o)
    add(kpq, o, {{p[o], AccessMode::R}, {q[o], AccessMode::R}, {pq, AccessMode::CW}}, true);
  add(ks, kNoObject, {{pq, AccessMode::R}, {rr, AccessMode::R}, {alpha, AccessMode::W}}, true);
  for (std::uint32_t o = 0; o < objects; ++o)
    add(ku, o,
        {{alpha, AccessMode::R},
         {q[o], AccessMode::R},
         {x[o], AccessMode::RW},
         {r[o], AccessMode::RW}},
        true);
  for (std::uint32_t o = 0; o < objects; ++o)
    add(krr, o, {{r[o], AccessMode::R}, {rr, AccessMode::CW}}, true);
  add(kres, kNoObject, {{rr, AccessMode::R}, {beta, AccessMode::W}, {cond, AccessMode::W}}, true);
  for (std::uint32_t o = 0; o < objects; ++o)
    add(kdir, o, {{r[o], AccessMode::R}, {beta, AccessMode::R}, {p[o], AccessMode::RW}}, true);
  add(kb, kNoObject, {{cond, AccessMode::R}}, true);
  loop.last = static_cast<TaskId>(g.tasks.size());
  g.loops.push_back(loop);
  return g;
}

void BM_DeriveEdges(benchmark::State& state) {
  // Built once per size: Google Benchmark calls this function several times per repetition.
  static std::map<std::int64_t, StepGraph> graphs;
  auto found = graphs.find(state.range(0));
  if (found == graphs.end())
    found = graphs.emplace(state.range(0), physics_like(static_cast<std::uint32_t>(state.range(0))))
                .first;
  StepGraph& g = found->second;
  for (auto _ : state) {
    g.derive_edges();
    benchmark::DoNotOptimize(g.edges.data());
    benchmark::ClobberMemory();
  }
  const auto it = static_cast<double>(state.iterations());
  const auto tasks = static_cast<double>(g.tasks.size());
  state.counters["tasks"] = tasks;
  state.counters["accesses_per_s"] =
      benchmark::Counter(it * static_cast<double>(g.accesses.size()), benchmark::Counter::kIsRate);
  state.counters["tasks_per_s"] = benchmark::Counter(it * tasks, benchmark::Counter::kIsRate);
  state.counters["edges_per_task"] =
      static_cast<double>(g.edges.size() + g.carried_edges.size()) / tasks;
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
  auto* derive = benchmark::RegisterBenchmark("BM_DeriveEdges", BM_DeriveEdges)
                     ->ArgName("tasks")
                     ->Unit(benchmark::kMicrosecond);
  for (int n : bench::by_size<std::vector<int>>(size, {1000}, {1000, 100000},
                                                {1000, 10000, 100000, 1000000}))
    derive->Arg(n);
  bench::timed(derive, size, 0.5);
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
