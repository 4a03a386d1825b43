// SPDX-License-Identifier: MIT
// Random step graphs with CW groups and loops, and the execution-order check, for tests.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "tgraph/graph/assignment.hpp"
#include "tgraph/graph/step_graph.hpp"
#include "tgraph/replay/executor.hpp"
#include "tgraph/replay/observer.hpp"
#include "tgraph/replay/synthetic.hpp"

namespace tgraph::replay::test {

/// Tasks of kind "t" on one object, each with the given accesses, in program order, over
/// `data` data of 8 bytes ("d0", "d1", ...).
inline StepGraph chain_graph(const std::vector<std::vector<Access>>& tasks, std::size_t data) {
  StepGraph g;
  const KindId kind = g.intern_kind("t");
  g.objects.push_back({"o"});
  for (std::size_t d = 0; d < data; ++d) g.data.push_back({"d" + std::to_string(d), 0, 8});
  for (std::size_t i = 0; i < tasks.size(); ++i)
    g.add_task(kind, 0, tasks[i], 0, static_cast<StableKey>(i + 1));
  g.derive_edges();
  return g;
}

/// A random program: straight-line segments and do-while loops whose body ends with a task
/// writing the condition and the break reading it. Accesses: R 40%, CW 30%, W 15%, RW 15%.
inline StepGraph random_graph(std::uint32_t seed, int segments = 4, int per_segment = 10,
                              int data = 8) {
  std::mt19937 rng(seed);
  auto pick = [&](int n) { return static_cast<int>(rng() % static_cast<unsigned>(n)); };
  StepGraph g;
  for (const char* k : {"a", "b", "c", "f"}) g.intern_kind(k);
  const KindId brk = g.intern_kind("loop.break");
  for (int o = 0; o < 4; ++o) g.objects.push_back({"obj" + std::to_string(o)});
  for (int d = 0; d < data; ++d)
    g.data.push_back({"d" + std::to_string(d), static_cast<ObjectId>(d % 4),
                      static_cast<std::uint64_t>(64 + 64 * pick(16))});
  auto add_random = [&](LoopId loop) {
    std::vector<Access> acc;
    const int n = 1 + pick(3);
    for (int i = 0; i < n; ++i) {
      const auto d = static_cast<DatumId>(pick(data));
      bool dup = false;
      for (const Access& a : acc) dup = dup || a.datum == d;
      if (dup) continue;
      const int r = pick(100);
      const AccessMode m = r < 40   ? AccessMode::R
                           : r < 70 ? AccessMode::CW
                           : r < 85 ? AccessMode::W
                                    : AccessMode::RW;
      acc.push_back({d, m});
    }
    // One pick per statement: the order of a call's arguments is unspecified (g++ and
    // clang differ), and the graph of a seed must not depend on the compiler.
    const auto kind = static_cast<KindId>(pick(4));
    const auto object = static_cast<ObjectId>(pick(4));
    const auto cost = static_cast<std::uint64_t>(pick(2000));
    const TaskId t = g.add_task(kind, object, acc, cost);
    g.tasks[t].loop = loop;
  };
  for (int s = 0; s < segments; ++s) {
    if (s % 2 == 1) {
      const auto cond = static_cast<DatumId>(g.data.size());
      g.data.push_back({"cond" + std::to_string(s), kNoObject, 8});
      const auto l = static_cast<LoopId>(g.loops.size());
      Loop loop;
      loop.condition = cond;
      loop.first = static_cast<TaskId>(g.tasks.size());
      loop.iterations = 1 + static_cast<std::uint32_t>(pick(4));
      loop.max_iterations =
          pick(2) == 0 ? 0 : loop.iterations + static_cast<std::uint32_t>(pick(3));
      for (int i = 0; i < per_segment; ++i) add_random(l);
      // The residual: reads some data, writes the condition.
      const Access res[] = {{static_cast<DatumId>(pick(data)), AccessMode::R},
                            {cond, AccessMode::W}};
      g.tasks[g.add_task(3, kNoObject, res, 300)].loop = l;
      const Access b[] = {{cond, AccessMode::R}};
      g.tasks[g.add_task(brk, kNoObject, b, 50)].loop = l;
      loop.last = static_cast<TaskId>(g.tasks.size());
      g.loops.push_back(loop);
    } else {
      for (int i = 0; i < per_segment; ++i) add_random(kNoLoop);
    }
  }
  for (TaskId t = 0; t < g.tasks.size(); ++t) g.tasks[t].key = t + 1;
  g.derive_edges();
  EXPECT_EQ(g.validate(), "");
  return g;
}

/// A random assignment on k processors (program order).
/// A dot product in a loop, as in a conjugate gradient: per object o (on processor o % k),
/// "partial" (R v_o, CW dot: each processor's partial sums end in one reducer on processor
/// 0 after lowering); "scalar" (R dot, W s) on processor 0; per object "update" (R s, RW
/// v_o); "residual" (R s, W cond) and the break on processor 0. Costs: `slow_ns` for the
/// partial tasks of processor `slow`'s objects, 0 for every other task.
struct DotLoop {
  StepGraph g;
  Assignment a;
};
inline DotLoop dot_loop(std::uint32_t objects, std::uint32_t k, std::uint32_t iterations,
                        ProcId slow, std::uint64_t slow_ns) {
  DotLoop d;
  StepGraph& g = d.g;
  const KindId partial = g.intern_kind("partial"), scalar = g.intern_kind("scalar"),
               update = g.intern_kind("update"), residual = g.intern_kind("residual"),
               brk = g.intern_kind("loop.break");
  for (std::uint32_t o = 0; o < objects; ++o) {
    g.objects.push_back({"o" + std::to_string(o)});
    g.data.push_back({"v" + std::to_string(o), o, 64});
  }
  const auto dot = static_cast<DatumId>(objects), s = dot + 1, cond = dot + 2;
  g.data.push_back({"dot", kNoObject, 8});
  g.data.push_back({"s", kNoObject, 8});
  g.data.push_back({"cond", kNoObject, 8});
  const auto add = [&](KindId kind, ObjectId o, std::vector<Access> acc, std::uint64_t cost) {
    const TaskId t = g.add_task(kind, o, acc, cost, static_cast<StableKey>(g.tasks.size() + 1));
    g.tasks[t].loop = 0;
    d.a.proc.push_back(o == kNoObject ? 0 : o % k);
  };
  for (std::uint32_t o = 0; o < objects; ++o)
    add(partial, o, {{o, AccessMode::R}, {dot, AccessMode::CW}}, o % k == slow ? slow_ns : 0);
  add(scalar, kNoObject, {{dot, AccessMode::R}, {s, AccessMode::W}}, 0);
  for (std::uint32_t o = 0; o < objects; ++o)
    add(update, o, {{s, AccessMode::R}, {o, AccessMode::RW}}, 0);
  add(residual, kNoObject, {{s, AccessMode::R}, {cond, AccessMode::W}}, 0);
  add(brk, kNoObject, {{cond, AccessMode::R}}, 0);
  g.loops.push_back({cond, 0, static_cast<TaskId>(g.tasks.size()), iterations, 0});
  d.a.k = k;
  g.derive_edges();
  return d;
}

inline Assignment random_assignment(const StepGraph& g, std::uint32_t k, std::uint32_t seed) {
  std::mt19937 rng(seed);
  Assignment a;
  a.k = k;
  for (std::size_t t = 0; t < g.tasks.size(); ++t) a.proc.push_back(static_cast<ProcId>(rng() % k));
  return a;
}

/// Options of a partition executor on `k` threads, run by the serial twin (`serial`) or by
/// the threads, which spin `spin_ns` before parking.
inline ExecOptions partition_options(std::uint32_t k, bool serial = false,
                                     std::int64_t spin_ns = kDefaultSpinNs) {
  ExecOptions o;
  o.threads = k;
  o.partition.serial = serial;
  o.spin_ns = spin_ns;
  return o;
}

/// What expect_valid_order() checks.
struct OrderCheck {
  /// Match the events by exec task id (g is the exec graph, whose edges the executors
  /// promise); else by original task id.
  bool exec = false;
  /// Only read-after-write edges (lowering may relax WAR/WAW edges of CW writers that it
  /// redirects to temporaries; true data dependencies always hold).
  bool raw_only = false;
  /// Iteration i + 1 of a loop starts after the break of iteration i (every policy but
  /// StarPU's unrolled loops, which have no gate).
  bool loop_gate = true;
};

/// Checks from a timeline (one step) that every task ran exactly runs(t) times and after
/// all its predecessors: intra-step and loop-carried edges, the loop gate and its own
/// previous iteration.
inline void expect_valid_order(const StepGraph& g, const std::vector<TimelineTask>& events,
                               std::uint32_t step, OrderCheck check = {}) {
  const bool exec = check.exec, raw_only = check.raw_only;
  std::map<std::pair<TaskId, std::uint32_t>, std::pair<std::int64_t, std::int64_t>> when;
  std::vector<std::uint32_t> count(g.tasks.size(), 0);
  for (const TimelineTask& e : events) {
    if (e.step != step || (!exec && !e.origin)) continue;
    const TaskId id = exec ? e.task : *e.origin;
    ASSERT_LT(id, g.tasks.size());
    ++count[id];
    ASSERT_TRUE(
        when.emplace(std::make_pair(id, e.iteration), std::make_pair(e.start_ns, e.end_ns)).second)
        << "task " << id << " iteration " << e.iteration << " ran twice";
  }
  for (TaskId t = 0; t < g.tasks.size(); ++t)
    ASSERT_EQ(count[t], g.runs(t)) << "task " << t << " ran " << count[t] << " times";
  auto end_of = [&](TaskId t, std::uint32_t i) { return when.at({t, i}).second; };
  auto start_of = [&](TaskId t, std::uint32_t i) { return when.at({t, i}).first; };
  for (const Edge& e : g.edges) {
    if (raw_only && e.kind != EdgeKind::RAW) continue;
    const LoopId lu = g.tasks[e.from].loop, lv = g.tasks[e.to].loop;
    for (std::uint32_t i = 0; i < g.runs(e.to); ++i) {
      const std::uint32_t iu =
          (lu != kNoLoop && lu == lv) ? i : static_cast<std::uint32_t>(g.runs(e.from) - 1);
      EXPECT_GE(start_of(e.to, i), end_of(e.from, iu))
          << "edge " << e.from << " -> " << e.to << " violated at iteration " << i;
    }
  }
  for (const Edge& e : g.carried_edges) {
    if (raw_only && e.kind != EdgeKind::RAW) continue;
    for (std::uint32_t i = 1; i < g.runs(e.to); ++i)
      EXPECT_GE(start_of(e.to, i), end_of(e.from, i - 1))
          << "carried edge " << e.from << " -> " << e.to << " violated at iteration " << i;
  }
  for (const Loop& l : g.loops)
    for (TaskId v = l.first; v < l.last; ++v)
      for (std::uint32_t i = 1; i < l.iterations; ++i) {
        if (check.loop_gate) {
          EXPECT_GE(start_of(v, i), end_of(l.last - 1, i - 1)) << "gate of loop, task " << v;
        }
        EXPECT_GE(start_of(v, i), end_of(v, i - 1)) << "task " << v << " overtook itself";
      }
}

/// A workload that throws in iteration 0 of task `bad` (original id) and stops every loop
/// after iteration 1; `set_known` makes it announce its loops' iteration counts.
class Throwing : public Workload {
 public:
  explicit Throwing(TaskId bad) : bad_(bad) {}
  void run(const TaskRun& r) override {
    if (r.origin == bad_ && r.iteration == 0)
      throw std::runtime_error("task " + std::to_string(bad_) + " failed");
  }
  bool stop_after(LoopId, std::uint32_t it) override { return it >= 1; }
  std::optional<std::uint32_t> known_iterations(LoopId) const override { return known_; }
  void set_known(std::optional<std::uint32_t> n) { known_ = n; }

 private:
  TaskId bad_;
  std::optional<std::uint32_t> known_;
};

/// Final words of the original data after the steps `w` ran.
inline std::vector<std::vector<std::uint64_t>> final_state(const SyntheticWorkload& w,
                                                           const StepGraph& g) {
  std::vector<std::vector<std::uint64_t>> s;
  for (DatumId d = 0; d < g.data.size(); ++d) {
    auto words = w.words(d);
    s.emplace_back(words.begin(), words.end());
  }
  return s;
}

/// Final words of the original data after `steps` sequential steps of g.
inline std::vector<std::vector<std::uint64_t>> sequential_state(const StepGraph& g, int steps) {
  auto ex = make_executor(Policy::kSequential, {});
  SyntheticWorkload w({.cost_scale = 0.0});
  w.set_step(g);
  for (int s = 0; s < steps; ++s) ex->run_step(g, nullptr, w);
  return final_state(w, g);
}

}  // namespace tgraph::replay::test
