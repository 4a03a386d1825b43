// SPDX-License-Identifier: MIT
// Replay benchmarks, side by side in one run:
//  * Handoff/<work_ns>/<spin_ns>: a loop whose body alternates two processors, so every
//    iteration is two cross-thread hand-offs after `work_ns` of work each. Per hand-off
//    overhead = time per iteration / 2 - work. Where the spin budget is shorter than the
//    wait, the waiter parks (futex) and the hand-off costs microseconds: the switch point.
//  * Policy/<policy>/threads:N: a synthetic bars64-like step (64 bars, a CG loop of 25
//    iterations with per-bar matrix products and global dot products) under each policy.
//  * TaskOverhead/<policy>/threads:N: the same step with empty bodies (no spin, no data):
//    what each executor costs per task instance (ns_per_task): sequential, partition,
//    worksteal, barrier, and starpu when the build has StarPU; per step, the signals
//    published, the waits that blocked and those that parked; `core_speed`,
//    `probe_step_us`, `probe_alone_us` and `probe_handoff_ns` as below, probed after the
//    repetition's steps.
//  * TaskOverheadInTurn/threads:N: partition / sequential per empty task, the two executors
//    run in turn in blocks of steps within one benchmark iteration (`ratio`: the median over
//    the iterations of the two blocks' median step times), so that a change of the host's
//    speed between repetitions, which this project's VM shows in spells, falls on both.
//    A third block runs partition with PartitionOptions::combine off (`ratio_uncombined`,
//    `ratio_quiet_uncombined`): what the combined reductions save, in the same pairs.
//    After each pair of blocks, the host is probed (probe_host()): `probe_handoff_ns`, two
//    threads bouncing a counter, and `core_speed` (p10, p90), the second thread's core's
//    speed over the first's when both run the same empty steps at once: 1 on a quiet machine;
//    `probe_step_us`, the first thread's median step meanwhile (its core's own speed).
//    `probe_alone_us`: the same step on the first thread with the second gone.
//    `ratio_quiet`: the median ratio over the `quiet_pairs`, those whose probes before and
//    after found equal core speeds, the first core as fast beside the second as alone, and
//    near its fastest.
//  * OmpTasks/<cw>/<wait>/threads:N: the Policy step under omp-tasks, CW lowered per writer
//    (inout + reducer task) or left whole as mutexinoutset, with or without a taskwait per
//    CG iteration: which way of writing it a competent OpenMP user should pick here.
//  * SignalWait/<spin|futex>: the floor under a hand-off: two threads bouncing a counter
//    through one std::atomic, by spinning on it or by std::atomic::wait/notify_one;
//    latency_ns is one signal -> wait (half a round trip).
#include <algorithm>
#include <atomic>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "bench_main.hpp"
#include "tgraph/graph/median.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/observer.hpp"
#include "tgraph/replay/synthetic.hpp"
#include "tgraph/replay/thread_binding.hpp"

namespace tgraph::replay {
namespace {

/// x -> y ping-pong: A (p0) reads y writes x, B (p1) reads x writes y, then the break (p0).
StepGraph ping_pong(std::uint64_t work_ns, std::uint32_t iterations) {
  StepGraph g;
  g.intern_kind("a");
  g.intern_kind("b");
  g.intern_kind("loop.break");
  g.data = {{"x", kNoObject, 8}, {"y", kNoObject, 8}, {"cond", kNoObject, 8}};
  const Access a[] = {{1, AccessMode::R}, {0, AccessMode::W}};
  const Access b[] = {{0, AccessMode::R}, {1, AccessMode::W}, {2, AccessMode::W}};
  const Access brk[] = {{2, AccessMode::R}};
  g.add_task(0, kNoObject, a, work_ns, 1);
  g.add_task(1, kNoObject, b, work_ns, 2);
  g.add_task(2, kNoObject, brk, 0, 3);
  for (Task& t : g.tasks) t.loop = 0;
  g.loops.push_back({2, 0, 3, iterations, 0});
  g.derive_edges();
  return g;
}

void BM_Handoff(benchmark::State& state) {
  const auto work = static_cast<std::uint64_t>(state.range(0));
  const std::int64_t spin = state.range(1);
  const std::uint32_t iterations = 200;
  const StepGraph g = ping_pong(work, iterations);
  Assignment a{2, {0, 1, 1}, {}};  // the break runs on p1 so p0 waits for it too
  ExecOptions o;
  o.threads = 2;
  o.spin_ns = spin;
  auto ex = make_executor(Policy::kPartition, o);
  SyntheticWorkload w({.cost_scale = 1.0, .touch = false});
  w.set_step(g);
  ex->run_step(g, &a, w);
  std::int64_t parks = 0;
  for (auto _ : state) parks += static_cast<std::int64_t>(ex->run_step(g, &a, w).parks());
  state.SetItemsProcessed(state.iterations() * iterations * 2);
  state.counters["handoff_ns"] =
      benchmark::Counter(static_cast<double>(state.iterations() * iterations * 2),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["parks_per_step"] =
      static_cast<double>(parks) / static_cast<double>(state.iterations());
}
/// A bars64-like step: per bar b: addForce (CW f_b); CG loop: per bar addDForce (R p_b,
/// W q_b), dot pq (R p_b q_b, CW pq), scalars, per bar cgUpdate (R q_b, RW x_b r_b), dot rr
/// (R r_b, CW rr), residual (R rr, W cond), per bar cgDirection (R r_b, RW p_b), break.
StepGraph bars_like(std::uint32_t bars, std::uint32_t iterations) {
  StepGraph g;
  const KindId kf = g.intern_kind("addForce"), kd = g.intern_kind("addDForce"),
               kpq = g.intern_kind("dotPQ"), ks = g.intern_kind("cgScalars"),
               ku = g.intern_kind("cgUpdate"), krr = g.intern_kind("dotRR"),
               kres = g.intern_kind("residual"), kdir = g.intern_kind("cgDirection"),
               kb = g.intern_kind("loop.break");
  const std::uint64_t vec = 256 * 3 * 8;  // 256 nodes x 3 doubles
  std::vector<DatumId> f, p, q, x, r;
  for (std::uint32_t b = 0; b < bars; ++b) {
    g.objects.push_back({"bar" + std::to_string(b)});
    for (auto* v : {&f, &p, &q, &x, &r}) {
      v->push_back(static_cast<DatumId>(g.data.size()));
      g.data.push_back({"bar" + std::to_string(b) + ".v" + std::to_string(v->size()), b, vec});
    }
  }
  const auto pq = static_cast<DatumId>(g.data.size());
  g.data.push_back({"pq", kNoObject, 8});
  g.data.push_back({"alpha", kNoObject, 8});
  g.data.push_back({"rr", kNoObject, 8});
  g.data.push_back({"cond", kNoObject, 8});
  const DatumId alpha = pq + 1, rr = pq + 2, cond = pq + 3;
  for (std::uint32_t b = 0; b < bars; ++b) {
    const Access acc[] = {{x[b], AccessMode::R}, {f[b], AccessMode::CW}};
    g.add_task(kf, b, acc, 5000);
  }
  Loop loop;
  loop.condition = cond;
  loop.first = static_cast<TaskId>(g.tasks.size());
  loop.iterations = iterations;
  auto add = [&](KindId k, ObjectId o, std::initializer_list<Access> acc, std::uint64_t cost) {
    const std::vector<Access> v(acc);
    g.tasks[g.add_task(k, o, v, cost)].loop = 0;
  };
  for (std::uint32_t b = 0; b < bars; ++b)
    add(kd, b, {{p[b], AccessMode::R}, {q[b], AccessMode::W}}, 7000);
  for (std::uint32_t b = 0; b < bars; ++b)
    add(kpq, b, {{p[b], AccessMode::R}, {q[b], AccessMode::R}, {pq, AccessMode::CW}}, 300);
  add(ks, kNoObject, {{pq, AccessMode::R}, {rr, AccessMode::R}, {alpha, AccessMode::W}}, 100);
  for (std::uint32_t b = 0; b < bars; ++b)
    add(ku, b,
        {{alpha, AccessMode::R},
         {q[b], AccessMode::R},
         {x[b], AccessMode::RW},
         {r[b], AccessMode::RW}},
        600);
  for (std::uint32_t b = 0; b < bars; ++b)
    add(krr, b, {{r[b], AccessMode::R}, {rr, AccessMode::CW}}, 300);
  add(kres, kNoObject, {{rr, AccessMode::R}, {cond, AccessMode::W}}, 100);
  for (std::uint32_t b = 0; b < bars; ++b)
    add(kdir, b, {{r[b], AccessMode::R}, {rr, AccessMode::R}, {p[b], AccessMode::RW}}, 400);
  add(kb, kNoObject, {{cond, AccessMode::R}}, 50);
  loop.last = static_cast<TaskId>(g.tasks.size());
  g.loops.push_back(loop);
  g.derive_edges();
  return g;
}

/// Owner-compute: bar b on processor b * k / bars, shared scalar tasks on processor 0.
Assignment owner_like(const StepGraph& g, std::uint32_t k, std::uint32_t bars) {
  Assignment a;
  a.k = k;
  for (const Task& t : g.tasks) a.proc.push_back(t.object == kNoObject ? 0 : t.object * k / bars);
  return a;
}

/// A bars64-like step, its owner-compute assignment and an executor of `policy` at the
/// benchmark's thread count (its first argument).
struct BarsRun {
  StepGraph g;
  Assignment a;
  std::unique_ptr<Executor> ex;
};

BarsRun bars_run(const benchmark::State& state, Policy policy) {
  const auto k = static_cast<std::uint32_t>(state.range(0));
  BarsRun r;
  r.g = bars_like(64, 25);
  r.a = owner_like(r.g, k, 64);
  ExecOptions o;
  o.threads = k;
  r.ex = make_executor(policy, o);
  return r;
}

void BM_Policy(benchmark::State& state, Policy policy) {
  const BarsRun r = bars_run(state, policy);
  SyntheticWorkload w;
  w.set_step(r.g);
  r.ex->run_step(r.g, &r.a, w);
  for (auto _ : state) r.ex->run_step(r.g, &r.a, w);
}

/// The state of the host at this moment, for reading a ratio measured next to it.
struct HostProbe {
  double handoff_ns = 0;  ///< one way, two threads bouncing a counter
  double core_speed = 0;  ///< thread 1's core's speed over thread 0's, both busy at once
  double step_us = 0;     ///< thread 0's median empty step meanwhile (its core's own speed)
  double alone_us = 0;    ///< the same on thread 0 with thread 1 gone (no neighbour's load)
};

/// Two threads on thread slots 0 and 1's cores (the calling thread for the probe's length,
/// as the executors pin their threads 0 and 1):
/// first they bounce a counter (half the median round trip over blocks of 100), then each
/// runs the same block of sequential empty steps of `g` at the same time (its own executor
/// and workload; median step time t0, t1; core_speed = t0 / t1). On this project's VM the
/// hand-off stays near 33 ns while the two vCPUs' speeds move apart in spells of
/// milliseconds to seconds: a block of bars64-like empty steps takes 120 us on a vCPU in its
/// fast state and about 200 us in its slow one, often one vCPU in each.
HostProbe probe_host(const StepGraph& g) {
  HostProbe h;
  if (hardware_pus() < 2) return h;
  BindingScope binding;  // the calling thread's binding, restored on return
  binding.pin(0);
  constexpr int kBlocks = 20, kRounds = 100, kSteps = 50;
  const auto step_time = [&g] {
    std::unique_ptr<Executor> ex = make_executor(Policy::kSequential, ExecOptions{});
    SyntheticWorkload w({.cost_scale = 0.0, .touch = false});
    w.set_step(g);
    ex->run_step(g, nullptr, w);
    std::vector<double> walls(kSteps);
    for (double& t : walls) t = static_cast<double>(ex->run_step(g, nullptr, w).wall_ns);
    return median(walls);
  };
  // acquire/release: as an executor's completion counter (each side reads the other's
  // write); the counter also starts the two blocks of steps together.
  std::atomic<std::uint64_t> counter{0};
  double t1 = 0;
  std::thread partner([&] {
    BindingScope partner_binding;
    partner_binding.pin(1);
    for (std::uint64_t v = 1; v < 2ull * kBlocks * kRounds; v += 2) {
      while (counter.load(std::memory_order_acquire) != v) cpu_relax();
      counter.store(v + 1, std::memory_order_release);
    }
    while (counter.load(std::memory_order_acquire) != 2ull * kBlocks * kRounds + 1) cpu_relax();
    t1 = step_time();
  });
  std::vector<double> half_round_trips;
  std::uint64_t next = 1;
  for (int b = 0; b < kBlocks; ++b) {
    const std::int64_t t0 = now_ns();
    for (int r = 0; r < kRounds; ++r, next += 2) {
      counter.store(next, std::memory_order_release);
      while (counter.load(std::memory_order_acquire) != next + 1) cpu_relax();
    }
    half_round_trips.push_back(static_cast<double>(now_ns() - t0) / (2.0 * kRounds));
  }
  counter.store(next, std::memory_order_release);
  const double t0 = step_time();
  partner.join();
  h.handoff_ns = median(half_round_trips);
  h.core_speed = t0 / t1;
  h.step_us = t0 / 1e3;
  h.alone_us = step_time() / 1e3;
  return h;
}

void BM_TaskOverhead(benchmark::State& state, Policy policy) {
  const BarsRun r = bars_run(state, policy);
  const StepGraph& g = r.g;
  const Assignment& a = r.a;
  Executor* ex = r.ex.get();
  SyntheticWorkload w({.cost_scale = 0.0, .touch = false});
  w.set_step(g);
  const ExecStepStats first = ex->run_step(g, &a, w);
  std::uint64_t instances = 0;
  for (const ThreadCounters& c : first.threads) instances += c.tasks;
  std::uint64_t signals = 0, blocked = 0, parks = 0, waits = 0;
  std::int64_t wait_ns = 0, prepare = 0;
  for (auto _ : state) {
    const ExecStepStats s = ex->run_step(g, &a, w);
    waits += s.waits();
    wait_ns += s.wait_ns();
    prepare += s.prepare_ns;
    signals += s.signals();
    blocked += s.blocked_waits();
    parks += s.parks();
  }
  const auto steps = static_cast<double>(state.iterations());
  // The host right after the timed steps (probe_host()): core_speed 1 on a quiet machine;
  // probe_step_us, thread 0's core's own speed, compares repetitions run at different times.
  const HostProbe host = probe_host(g);
  state.counters["core_speed"] = host.core_speed;
  state.counters["probe_step_us"] = host.step_us;
  state.counters["probe_alone_us"] = host.alone_us;
  state.counters["probe_handoff_ns"] = host.handoff_ns;
  state.counters["signals_per_step"] = static_cast<double>(signals) / steps;
  state.counters["blocked_per_step"] = static_cast<double>(blocked) / steps;
  state.counters["parks_per_step"] = static_cast<double>(parks) / steps;
  state.counters["waits_per_step"] = static_cast<double>(waits) / steps;
  state.counters["wait_us_per_step"] = static_cast<double>(wait_ns) / steps / 1e3;
  state.counters["prepare_us_per_step"] = static_cast<double>(prepare) / steps / 1e3;
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * instances));
  state.counters["ns_per_task"] =
      benchmark::Counter(static_cast<double>(state.iterations() * instances),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_TaskOverheadInTurn(benchmark::State& state, std::uint32_t block) {
  const auto k = static_cast<std::uint32_t>(state.range(0));
  const StepGraph g = bars_like(64, 25);
  const Assignment a = owner_like(g, k, 64);
  ExecOptions o;
  o.threads = k;
  std::unique_ptr<Executor> seq = make_executor(Policy::kSequential, o);
  std::unique_ptr<Executor> par = make_executor(Policy::kPartition, o);
  ExecOptions uncombined = o;  // the same executor with every task on its own processor
  uncombined.partition.combine = false;
  std::unique_ptr<Executor> apart = make_executor(Policy::kPartition, uncombined);
  SyntheticWorkload w({.cost_scale = 0.0, .touch = false});
  w.set_step(g);
  std::uint64_t instances = 0;
  for (const ThreadCounters& c : seq->run_step(g, nullptr, w).threads) instances += c.tasks;
  par->run_step(g, &a, w);
  apart->run_step(g, &a, w);
  std::vector<double> ratios, apart_ratios, seq_ns, par_ns, handoff, core_speed, probe_step,
      probe_alone, walls(block);
  // The host probed before and after each pair (the after of one is the before of the next).
  std::vector<HostProbe> probes{probe_host(g)};
  for (auto _ : state) {
    // Each executor's block follows the others', the order reversed every other iteration.
    const auto time_block = [&](Executor& ex, const Assignment* as) {
      for (std::uint32_t i = 0; i < block; ++i)
        walls[i] = static_cast<double>(ex.run_step(g, as, w).wall_ns);
      return median(walls);
    };
    double s = 0, p = 0, n = 0;
    if (ratios.size() % 2 == 0) {
      s = time_block(*seq, nullptr);
      p = time_block(*par, &a);
      n = time_block(*apart, &a);
    } else {
      n = time_block(*apart, &a);
      p = time_block(*par, &a);
      s = time_block(*seq, nullptr);
    }
    ratios.push_back(p / s);
    apart_ratios.push_back(n / s);
    seq_ns.push_back(s);
    par_ns.push_back(p);
    const HostProbe h = probe_host(g);
    probes.push_back(h);
    handoff.push_back(h.handoff_ns);
    core_speed.push_back(h.core_speed);
    probe_step.push_back(h.step_us);
    probe_alone.push_back(h.alone_us);
  }
  // Quiet pairs: both probes around the pair found the two cores at the same speed (within
  // 5 %), the first core as fast with the second busy beside it as alone (within 10 %), and
  // alone within 10 % of its fastest of the run: neither a slow vCPU nor two vCPUs slowing
  // each other. ratio_quiet is the median over those pairs (0 when there are none): the
  // figure of a quiet machine, the pairs chosen by the probes, not by their ratios.
  double fastest = 0;
  for (const HostProbe& h : probes)
    if (h.alone_us > 0 && (fastest == 0 || h.alone_us < fastest)) fastest = h.alone_us;
  const auto quiet = [fastest](const HostProbe& h) {
    return h.core_speed >= 0.95 && h.core_speed <= 1.05 && h.step_us <= 1.10 * h.alone_us &&
           h.alone_us <= 1.10 * fastest;
  };
  std::vector<double> quiet_ratios, quiet_apart;
  for (std::size_t i = 0; i < ratios.size(); ++i)
    if (quiet(probes[i]) && quiet(probes[i + 1])) {
      quiet_ratios.push_back(ratios[i]);
      quiet_apart.push_back(apart_ratios[i]);
    }
  const auto per_task = static_cast<double>(instances);
  state.counters["ratio"] = median(ratios);
  state.counters["ratio_quiet"] = quiet_ratios.empty() ? 0.0 : median(quiet_ratios);
  // The same without combines (PartitionOptions::combine off), timed in the same pairs.
  state.counters["ratio_uncombined"] = median(apart_ratios);
  state.counters["ratio_quiet_uncombined"] = quiet_apart.empty() ? 0.0 : median(quiet_apart);
  state.counters["quiet_pairs"] = static_cast<double>(quiet_ratios.size());
  state.counters["sequential_ns_per_task"] = median(seq_ns) / per_task;
  state.counters["partition_ns_per_task"] = median(par_ns) / per_task;
  std::sort(ratios.begin(), ratios.end());
  state.counters["ratio_p10"] = ratios[ratios.size() / 10];
  state.counters["ratio_p90"] = ratios[ratios.size() * 9 / 10];
  // The host over the same iterations (probe_host()).
  state.counters["probe_handoff_ns"] = median(handoff);
  state.counters["core_speed"] = median(core_speed);
  state.counters["probe_step_us"] = median(probe_step);
  state.counters["probe_alone_us"] = median(probe_alone);
  std::sort(core_speed.begin(), core_speed.end());
  state.counters["core_speed_p10"] = core_speed[core_speed.size() / 10];
  state.counters["core_speed_p90"] = core_speed[core_speed.size() * 9 / 10];
}

void BM_OmpTasks(benchmark::State& state, bool mutex, bool iteration_wait) {
  const auto k = static_cast<std::uint32_t>(state.range(0));
  const StepGraph g = bars_like(64, 25);
  ExecOptions o;
  o.threads = k;
  o.reduce_scope = mutex ? ReduceScope::kNone : ReduceScope::kPerWriter;
  o.omp_tasks.iteration_wait = iteration_wait;
  auto ex = make_executor(Policy::kOmpTasks, o);
  SyntheticWorkload w;
  w.set_step(g);
  ex->run_step(g, nullptr, w);
  for (auto _ : state) ex->run_step(g, nullptr, w);
}

/// Two threads, one counter: the main thread publishes odd values, the partner answers each
/// with the next even one; `futex` waits with std::atomic::wait, else spins.
void BM_SignalWait(benchmark::State& state, bool futex) {
  constexpr std::uint64_t kRounds = 1000;
  // relaxed would not do: each side reads the other's write and must see what preceded it
  // (an acquire/release pair, as an executor's completion counter).
  std::atomic<std::uint64_t> counter{0};
  std::atomic<bool> stop{false};
  auto await = [&](std::uint64_t value) {
    if (futex) {
      for (std::uint64_t v = counter.load(std::memory_order_acquire); v != value;
           v = counter.load(std::memory_order_acquire))
        counter.wait(v, std::memory_order_acquire);
    } else {
      while (counter.load(std::memory_order_acquire) != value) cpu_relax();
    }
  };
  auto publish = [&](std::uint64_t value) {
    counter.store(value, std::memory_order_release);
    if (futex) counter.notify_one();
  };
  std::thread partner([&] {
    for (std::uint64_t v = 1;; v += 2) {
      if (futex) {
        for (std::uint64_t c = counter.load(std::memory_order_acquire); c != v;
             c = counter.load(std::memory_order_acquire)) {
          // relaxed: stop is only read to leave; the store below happens before the join.
          if (stop.load(std::memory_order_relaxed)) return;
          counter.wait(c, std::memory_order_acquire);
        }
      } else {
        while (counter.load(std::memory_order_acquire) != v) {
          if (stop.load(std::memory_order_relaxed)) return;  // relaxed: as above
          cpu_relax();
        }
      }
      publish(v + 1);
    }
  });
  std::uint64_t next = 1;
  for (auto _ : state) {
    for (std::uint64_t r = 0; r < kRounds; ++r, next += 2) {
      publish(next);
      await(next + 1);
    }
  }
  stop.store(true, std::memory_order_relaxed);      // relaxed: the partner only polls it
  counter.fetch_add(2, std::memory_order_release);  // leaves a value the partner does not wait for
  counter.notify_all();
  partner.join();
  state.counters["latency_ns"] =
      benchmark::Counter(static_cast<double>(state.iterations() * kRounds * 2),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void register_all(bench::Size size) {
  const bool smoke = size == bench::Size::kSmoke;
  for (const bool futex : {false, true})
    bench::timed(benchmark::RegisterBenchmark(futex ? "BM_SignalWait/futex" : "BM_SignalWait/spin",
                                              BM_SignalWait, futex)
                     ->Unit(benchmark::kMicrosecond)
                     ->UseRealTime(),
                 size, 0.3);
  auto* handoff = benchmark::RegisterBenchmark("BM_Handoff", BM_Handoff)
                      ->ArgNames({"work_ns", "spin_ns"})
                      ->Unit(benchmark::kMicrosecond)
                      ->UseRealTime();
  if (smoke)
    handoff->Args({0, 5'000});
  else
    handoff->ArgsProduct({{0, 2'000}, {0, 5'000, 50'000}});
  bench::timed(handoff, size, 0.3);

  std::vector<Policy> parallel = {Policy::kPartition, Policy::kWorksteal, Policy::kBarrier,
                                  Policy::kOmpTasks};
#ifdef TGRAPH_HAVE_STARPU
  parallel.push_back(Policy::kStarpu);
#endif
  const auto add = [&](const char* name, void (*fn)(benchmark::State&, Policy), Policy p,
                       std::vector<std::int64_t> threads) {
    auto* b = benchmark::RegisterBenchmark(
                  (std::string(name) + "/" + std::string(to_string(p))).c_str(), fn, p)
                  ->ArgName("threads")
                  ->Unit(benchmark::kMillisecond)
                  ->UseRealTime();
    for (const std::int64_t t : threads) b->Arg(t);
    bench::timed(b, size, 0.5);
  };
  add("BM_Policy", BM_Policy, Policy::kSequential, {1});
  if (!smoke)
    for (const Policy p : parallel) add("BM_Policy", BM_Policy, p, {2});
  if (!smoke)
    for (const bool mutex : {false, true})
      for (const bool wait : {true, false}) {
        const std::string name = std::string("BM_OmpTasks/") + (mutex ? "mutexinoutset" : "reduce") +
                                 (wait ? "/taskwait" : "/nowait");
        auto* b = benchmark::RegisterBenchmark(name.c_str(), BM_OmpTasks, mutex, wait)
                      ->ArgName("threads")
                      ->Arg(2)
                      ->Unit(benchmark::kMillisecond)
                      ->UseRealTime();
        bench::timed(b, size, 0.5);
      }
  add("BM_TaskOverhead", BM_TaskOverhead, Policy::kSequential, {1});
  {
    const auto block = bench::by_size<std::uint32_t>(size, 2, 100, 200);
    auto* b = benchmark::RegisterBenchmark("BM_TaskOverheadInTurn", BM_TaskOverheadInTurn, block)
                  ->ArgName("threads")
                  ->Unit(benchmark::kMillisecond)
                  ->UseRealTime()
                  ->Iterations(bench::by_size<benchmark::IterationCount>(size, 2, 20, 40));
    for (const std::int64_t t : {1, 2}) b->Arg(t);
  }
  for (const Policy p : parallel)
    add("BM_TaskOverhead", BM_TaskOverhead, p,
        smoke ? std::vector<std::int64_t>{2} : std::vector<std::int64_t>{1, 2});
}

}  // namespace
}  // namespace tgraph::replay

int main(int argc, char** argv) {
  return tgraph::bench::run_main(argc, argv, tgraph::replay::register_all);
}
