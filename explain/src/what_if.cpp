// SPDX-License-Identifier: MIT
// What-ifs: the step on the built-in simulator (tgraph::model::simulate) or its executed
// schedule re-run, with changed bodies, hand-offs, per-task gaps and serial phases.
#include "what_if.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "tgraph/graph/error.hpp"
#include "tgraph/model/simulator.hpp"

namespace tgraph::explain::detail {
namespace {

// How many objects get what-ifs: those with the most work.
constexpr std::size_t kObjects = 8;

// One change of the executed schedule.
struct Change {
  std::vector<double> task_scale;  ///< by executed task: bodies' duration factor (empty: 1)
  bool interruption_free = false;  ///< bodies at their CPU time
  bool inflation_free = false;     ///< bodies at their sequential cost (+ their interruption)
  bool runtime_free = false;       ///< no reducers, no time between a ready body and its start
  bool handoff_free = false;       ///< hand-offs of no latency
  bool parks_free = false;         ///< hand-offs after a park at the spinning ones' latency
  std::uint32_t balance_thread = kNone;  ///< this thread's bodies scaled by balance_scale
  double balance_scale = 1.0;
  std::int64_t serial = 0;  ///< the serial phases' new length
};

std::int64_t median(std::vector<std::int64_t> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// The measured shape of the schedule: per instance the time its thread spent before it
// (gap), the latency of its hand-off (lat), whether the wait before it parked.
struct Shape {
  std::vector<std::int64_t> gap, lat;
  std::vector<bool> parked;
  std::int64_t spin_latency = 0;  ///< median latency of hand-offs that did not park
  std::int64_t park_latency = 0;  ///< median latency of hand-offs after a park (0: none)
  std::int64_t spin_budget = 0;   ///< a waiter parks after spinning this long
  std::int64_t task_gap = 0;      ///< median time between a thread's bodies, not data-bound
  std::int64_t join = 0;          ///< from the last body's end to the step's end
};

Shape shape_of(const StepView& v) {
  const std::size_t n = v.instances.size();
  Shape sh;
  sh.gap.assign(n, 0);
  sh.lat.assign(n, 0);
  sh.parked.assign(n, false);
  std::vector<std::int64_t> bound, spinning, parking, gaps;
  std::vector<bool> data_bound(n, false);
  // Parked waits between a body and its thread's previous one (both lists by start).
  std::vector<std::vector<const Wait*>> parks(v.threads);
  for (const Wait& w : v.waits)
    if (w.parked && w.thread < v.threads) parks[w.thread].push_back(&w);
  for (std::uint32_t th = 0; th < v.threads; ++th) {
    std::size_t next = 0;
    for (const std::uint32_t k : v.by_thread[th]) {
      const Instance& i = v.instances[k];
      const std::int64_t a = i.prev == kNone ? 0 : v.instances[i.prev].end;
      while (next < parks[th].size() && parks[th][next]->end <= a) ++next;
      sh.parked[k] = next < parks[th].size() && parks[th][next]->start < i.start;
    }
  }
  for (std::size_t k = 0; k < n; ++k) {
    const Instance& i = v.instances[k];
    const std::int64_t a = i.prev == kNone ? 0 : v.instances[i.prev].end;
    const bool cross = i.latest != kNone && v.instances[i.latest].thread != i.thread;
    if (cross && i.ready > a) {
      data_bound[k] = true;
      sh.lat[k] = std::max<std::int64_t>(0, i.start - i.ready);
      bound.push_back(sh.lat[k]);
      (sh.parked[k] ? parking : spinning).push_back(sh.lat[k]);
    } else {
      sh.gap[k] = std::max<std::int64_t>(0, i.start - a);
      if (i.prev != kNone) gaps.push_back(sh.gap[k]);
    }
  }
  const std::int64_t typical = median(bound);
  sh.spin_latency = median(spinning);
  sh.park_latency = median(parking);
  sh.task_gap = median(gaps);
  // The spin budget lies between the longest wait that did not park and the shortest that
  // did: the former (a waiter that parks has spun that long at least).
  std::int64_t shortest_park = -1;
  for (const Wait& w : v.waits) {
    if (!w.parked) sh.spin_budget = std::max(sh.spin_budget, w.end - w.start);
    if (w.parked && (shortest_park < 0 || w.end - w.start < shortest_park))
      shortest_park = w.end - w.start;
  }
  if (shortest_park >= 0) sh.spin_budget = std::min(sh.spin_budget, shortest_park);
  for (std::size_t k = 0; k < n; ++k) {
    const Instance& i = v.instances[k];
    if (data_bound[k] || i.latest == kNone) continue;
    sh.lat[k] = std::clamp<std::int64_t>(typical, 0, std::max<std::int64_t>(0, i.start - i.ready));
  }
  std::int64_t last = 0;
  for (const Instance& i : v.instances) last = std::max(last, i.end);
  sh.join = std::max<std::int64_t>(0, v.wall - last);
  return sh;
}

// Instance i's body under change c (the runtime's reducers: 0 when the runtime is free).
double duration(const Instance& i, const Change& c) {
  double d = static_cast<double>(i.end - i.start);
  if (i.reducer) return c.runtime_free ? 0.0 : d;
  if (c.interruption_free) d -= static_cast<double>(i.interrupted());
  if (c.inflation_free)
    d = std::min(d, static_cast<double>(i.cost + (c.interruption_free ? 0 : i.interrupted())));
  if (!c.task_scale.empty()) d *= c.task_scale[i.task];
  if (i.thread == c.balance_thread) d *= c.balance_scale;
  return std::max(0.0, d);
}

// The executed schedule re-run under c: each thread's bodies in their order, each one
// after its thread's previous one (plus the measured gap) and its predecessors (plus the
// measured hand-off from another thread).
std::int64_t run(const StepView& v, const Shape& sh, const Change& c) {
  const std::size_t n = v.instances.size();
  std::vector<std::int64_t> end(n, -1);
  std::vector<std::int64_t> thread_end(v.threads, 0);
  std::int64_t last = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const Instance& i = v.instances[k];
    std::int64_t lat = sh.lat[k];
    if (c.handoff_free) lat = 0;
    if (c.parks_free && sh.parked[k]) lat = std::min(lat, sh.spin_latency);
    std::int64_t start = thread_end[i.thread] + (c.runtime_free ? 0 : sh.gap[k]);
    for (std::uint32_t p = i.pred_begin; p < i.pred_end; ++p) {
      const std::uint32_t u = v.preds[p];
      const Instance& pu = v.instances[u];
      const std::int64_t e = end[u] >= 0 ? end[u] : pu.end;
      start = std::max(start, e + (pu.thread != i.thread ? lat : 0));
    }
    end[k] = start + std::llround(duration(i, c));
    thread_end[i.thread] = end[k];
    last = std::max(last, end[k]);
  }
  return c.serial + last + (c.runtime_free ? 0 : sh.join);
}

// The step on the built-in simulator: its executed graph, each task on the thread that ran
// its first instance, each thread's tasks in the order they started, each task's cost its
// bodies' mean (measured, or as a change makes it), the machine's parameters as the
// timeline measured them (Shape): the spinning hand-offs' median latency, the parked ones'
// after the spin budget, the median gap between a thread's bodies as the per-task
// overhead. Empty when the timeline lacks instances of the step (sampled) or the order
// deadlocks the simulator.
class Simulated {
 public:
  static std::optional<Simulated> of(const StepView& v, const Shape& sh) {
    if (v.unobserved != 0 || v.threads == 0 || v.instances.empty()) return std::nullopt;
    Simulated s(v, sh);
    for (int attempt = 0; attempt < 2; ++attempt) {
      try {
        if (s.makespan(Change{}) <= 0) return std::nullopt;
        return s;
      } catch (const Error&) {
        // Threads that took tasks from each other (a loop task on one thread in some
        // iterations, another in others) can give start orders whose loop blocks deadlock:
        // program order cannot.
        s.a_.order.clear();
      }
    }
    return std::nullopt;
  }
  /// The simulated makespan under c (serial phases c.serial, as in run()).
  std::int64_t makespan(const Change& c) const {
    StepGraph g = g_;
    std::vector<double> sum(g.tasks.size(), 0.0);
    std::vector<std::uint32_t> count(g.tasks.size(), 0);
    for (const Instance& i : v_->instances) {
      sum[i.task] += duration(i, c);
      ++count[i.task];
    }
    for (TaskId t = 0; t < g.tasks.size(); ++t)
      g.tasks[t].cost_ns =
          count[t] == 0 ? 0 : static_cast<std::uint64_t>(std::llround(sum[t] / count[t]));
    model::CostModel m = m_;
    if (c.handoff_free) m.sync_latency_ns = 0;
    if (c.handoff_free || c.parks_free) m.park_wake_ns = 0;
    if (c.runtime_free) m.task_overhead_ns = 0;
    const model::Schedule s =
        model::simulate(g, a_, m, static_cast<std::uint64_t>(std::max<std::int64_t>(0, c.serial)));
    return static_cast<std::int64_t>(s.makespan_ns);
  }
 private:
  Simulated(const StepView& v, const Shape& sh) : v_(&v), m_(model::CostModel::ideal()) {
    const TimelineGraph& tg = *v.graph;
    const std::size_t n = tg.task_kind.size();
    g_.kinds = tg.kinds;
    for (const std::string& d : tg.data) g_.data.push_back({d, kNoObject, 0});
    if (g_.data.empty()) g_.data.push_back({"(none)", kNoObject, 0});
    g_.tasks.resize(n);
    for (TaskId t = 0; t < n; ++t) {
      g_.tasks[t].kind = tg.task_kind[t];
      g_.tasks[t].loop = tg.task_loop[t];
    }
    for (LoopId l = 0; l < tg.loops.size(); ++l) {
      const std::uint32_t it = v.info->iterations[l];
      g_.loops.push_back({0, tg.loops[l].first, tg.loops[l].second, it, it});
    }
    g_.edges = tg.edges;
    g_.carried_edges = tg.carried_edges;
    // Each task on the thread that ran most of its instances (the first on a tie); each
    // thread's tasks in the order their first instances started (instances are by start).
    a_.k = v.threads;
    a_.proc.assign(n, 0);
    std::vector<std::uint32_t> ran(n * v.threads, 0);
    for (const Instance& i : v.instances) ++ran[i.task * v.threads + i.thread];
    for (TaskId t = 0; t < n; ++t) {
      const auto row = ran.begin() + static_cast<std::ptrdiff_t>(t) * v.threads;
      a_.proc[t] = static_cast<ProcId>(std::max_element(row, row + v.threads) - row);
    }
    a_.order.resize(v.threads);
    std::vector<bool> placed(n, false);
    for (const Instance& i : v.instances) {
      if (placed[i.task]) continue;
      placed[i.task] = true;
      a_.order[a_.proc[i.task]].push_back(i.task);
    }
    for (TaskId t = 0; t < n; ++t)
      if (!placed[t]) a_.order[0].push_back(t);  // no instance (a loop run 0 times)
    m_.sync_latency_ns = static_cast<double>(sh.spin_latency);
    m_.park_wake_ns = static_cast<double>(sh.park_latency);
    m_.spin_budget_ns = static_cast<double>(sh.spin_budget);
    m_.task_overhead_ns = static_cast<double>(sh.task_gap);
  }

  const StepView* v_;
  StepGraph g_;
  Assignment a_;
  model::CostModel m_;
};

}  // namespace

std::int64_t predict_kind_faster(const StepView& v, std::int64_t serial_ns, KindId kind,
                                 double fraction) {
  const Shape sh = shape_of(v);
  Change c;
  c.serial = serial_ns;
  c.task_scale.assign(v.graph->task_kind.size(), 1.0);
  for (TaskId t = 0; t < c.task_scale.size(); ++t)
    if (v.graph->task_kind[t] == kind) c.task_scale[t] = 1.0 - fraction;
  return run(v, sh, c);
}

std::vector<WhatIf> what_ifs(const StepView& v, const StepExplanation& s, double fit,
                             std::int64_t* simulated_ns) {
  const Shape sh = shape_of(v);
  Change base;
  base.serial = s.serial_ns;
  const std::optional<Simulated> sim = Simulated::of(v, sh);
  const std::int64_t as_run = run(v, sh, base);
  const std::int64_t as_simulated = sim ? sim->makespan(base) : 0;
  if (simulated_ns != nullptr) *simulated_ns = as_simulated;
  // A simulator that does not reproduce the step unchanged does not predict its changes.
  const bool fits = as_simulated > 0 && s.makespan_ns > 0 &&
                    std::abs(static_cast<double>(as_simulated) / static_cast<double>(s.makespan_ns) -
                             1.0) <= fit;
  std::vector<WhatIf> out;
  // Each prediction the observed makespan scaled by the model's changed / unchanged time;
  // `simulated`: on the simulator when it has the step, else on the executed schedule.
  const auto add = [&](std::string target, std::string change, const Change& c, bool simulated,
                       const char* scope = "cause") {
    const bool on_sim = simulated && fits;
    const double ratio =
        on_sim ? static_cast<double>(sim->makespan(c)) / static_cast<double>(as_simulated)
        : as_run > 0 ? static_cast<double>(run(v, sh, c)) / static_cast<double>(as_run)
                     : 1.0;
    const std::int64_t p = std::llround(ratio * static_cast<double>(s.makespan_ns));
    out.push_back({std::move(target), std::move(change), p, s.makespan_ns - p,
                   on_sim ? "simulator" : "executed_schedule", scope});
  };
  // Bodies of the tasks `of` says (a kind's, an object's) 10 % and 50 % shorter.
  const TimelineGraph& g = *v.graph;
  const auto faster = [&](const std::string& target, const char* scope, auto of) {
    for (const double f : {0.1, 0.5}) {
      Change c = base;
      c.task_scale.assign(g.task_kind.size(), 1.0);
      for (TaskId t = 0; t < g.task_kind.size(); ++t)
        if (g.origin[t] != kNoTask && of(t)) c.task_scale[t] = 1.0 - f;
      add(target, f == 0.1 ? "10% faster" : "50% faster", c, true, scope);
    }
  };
  std::vector<bool> present(g.kinds.size(), false);
  for (const Instance& i : v.instances)
    if (!i.reducer) present[g.task_kind[i.task]] = true;
  for (KindId k = 0; k < g.kinds.size(); ++k)
    if (present[k]) faster(g.kinds[k], "kind", [&](TaskId t) { return g.task_kind[t] == k; });
  // The objects with the most work (sequential cost), at most kObjects of them.
  if (g.task_object.size() == g.task_kind.size()) {
    std::vector<std::pair<std::int64_t, ObjectId>> work(g.objects.size());
    for (ObjectId o = 0; o < work.size(); ++o) work[o].second = o;
    for (const Instance& i : v.instances)
      if (!i.reducer && g.task_object[i.task] < work.size()) work[g.task_object[i.task]].first += i.cost;
    const std::size_t top = std::min(kObjects, work.size());
    std::partial_sort(work.begin(), work.begin() + static_cast<std::ptrdiff_t>(top), work.end(),
                      [](const auto& x, const auto& y) {
                        return x.first != y.first ? x.first > y.first : x.second < y.second;
                      });
    for (std::size_t r = 0; r < top && work[r].first > 0; ++r) {
      const ObjectId o = work[r].second;
      faster(g.objects[o], "object", [&](TaskId t) { return g.task_object[t] == o; });
    }
  }
  // Causes free: on the simulator where it has the parameter (hand-off latencies, the
  // per-task overhead, serial phases), else on the executed schedule (a body's own
  // inflation or interruption, one thread's load: the simulator sees a task's mean body).
  const auto free = [&](const char* target, bool Change::*flag, bool simulated) {
    Change c = base;
    c.*flag = true;
    add(target, "free", c, simulated);
  };
  free("handoff", &Change::handoff_free, true);
  if (std::find(sh.parked.begin(), sh.parked.end(), true) != sh.parked.end()) {
    Change c = base;
    c.parks_free = true;
    add("parks", "at the spinning hand-offs' latency", c, true);
  }
  free("runtime", &Change::runtime_free, true);
  free("inflation", &Change::inflation_free, false);
  free("interruption", &Change::interruption_free, false);
  const auto serial = [&](const char* target, std::int64_t ns) {
    Change c = base;
    c.serial = ns;
    add(target, "free", c, true);
  };
  if (s.serial_ns > v.info->host_ns) serial("serial", v.info->host_ns);
  if (v.info->partition_ns > 0) serial("partition", s.serial_ns - v.info->partition_ns);
  // The heaviest thread at the mean load.
  std::vector<std::int64_t> load(v.threads, 0);
  std::int64_t work = 0;
  for (const Instance& i : v.instances)
    if (!i.reducer) {
      load[i.thread] += i.cost;
      work += i.cost;
    }
  if (!load.empty() && work > 0) {
    const auto heavy = static_cast<std::uint32_t>(
        std::max_element(load.begin(), load.end()) - load.begin());
    const double mean = static_cast<double>(work) / static_cast<double>(v.threads);
    if (static_cast<double>(load[heavy]) > 1.01 * mean) {
      Change c = base;
      c.balance_thread = heavy;
      c.balance_scale = mean / static_cast<double>(load[heavy]);
      add("imbalance", "thread " + std::to_string(heavy) + " at the mean load", c, false);
    }
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const WhatIf& a, const WhatIf& b) { return a.gain > b.gain; });
  return out;
}

}  // namespace tgraph::explain::detail
