// SPDX-License-Identifier: MIT
// The executed schedule re-run with changed bodies, hand-offs, gaps and serial phases.
#include "what_if.hpp"

#include <algorithm>
#include <cmath>

namespace tgraph::explain::detail {
namespace {

// One change of the executed schedule.
struct Change {
  std::vector<double> kind_scale;  ///< by kind: bodies' duration factor (empty: 1)
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
  std::int64_t join = 0;          ///< from the last body's end to the step's end
};

Shape shape_of(const StepView& v) {
  const std::size_t n = v.instances.size();
  Shape sh;
  sh.gap.assign(n, 0);
  sh.lat.assign(n, 0);
  sh.parked.assign(n, false);
  std::vector<std::int64_t> bound, spinning;
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
      if (!sh.parked[k]) spinning.push_back(sh.lat[k]);
    } else {
      sh.gap[k] = std::max<std::int64_t>(0, i.start - a);
    }
  }
  const std::int64_t typical = median(bound);
  sh.spin_latency = median(spinning);
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
    double d = static_cast<double>(i.end - i.start);
    if (i.reducer) {
      if (c.runtime_free) d = 0;
    } else {
      if (c.interruption_free) d -= static_cast<double>(i.interrupted());
      if (c.inflation_free)
        d = std::min(d, static_cast<double>(i.cost + (c.interruption_free ? 0 : i.interrupted())));
      if (!c.kind_scale.empty()) d *= c.kind_scale[v.graph->task_kind[i.task]];
      if (i.thread == c.balance_thread) d *= c.balance_scale;
    }
    end[k] = start + std::llround(std::max(0.0, d));
    thread_end[i.thread] = end[k];
    last = std::max(last, end[k]);
  }
  return c.serial + last + (c.runtime_free ? 0 : sh.join);
}

}  // namespace

std::int64_t predict_kind_faster(const StepView& v, std::int64_t serial_ns, KindId kind,
                                 double fraction) {
  const Shape sh = shape_of(v);
  Change c;
  c.serial = serial_ns;
  c.kind_scale.assign(v.graph->kinds.size(), 1.0);
  if (kind < c.kind_scale.size()) c.kind_scale[kind] = 1.0 - fraction;
  return run(v, sh, c);
}

std::vector<WhatIf> what_ifs(const StepView& v, const StepExplanation& s) {
  const Shape sh = shape_of(v);
  Change base;
  base.serial = s.serial_ns;
  const std::int64_t as_run = run(v, sh, base);
  std::vector<WhatIf> out;
  const auto add = [&](std::string target, std::string change, const Change& c) {
    const std::int64_t p = run(v, sh, c);
    out.push_back({std::move(target), std::move(change), p, as_run - p});
  };
  const TimelineGraph& g = *v.graph;
  std::vector<bool> present(g.kinds.size(), false);
  for (const Instance& i : v.instances)
    if (!i.reducer) present[g.task_kind[i.task]] = true;
  for (KindId k = 0; k < g.kinds.size(); ++k) {
    if (!present[k]) continue;
    for (const double f : {0.1, 0.5}) {
      Change c = base;
      c.kind_scale.assign(g.kinds.size(), 1.0);
      c.kind_scale[k] = 1.0 - f;
      add(g.kinds[k], f == 0.1 ? "10% faster" : "50% faster", c);
    }
  }
  Change c = base;
  c.handoff_free = true;
  add("handoff", "free", c);
  if (std::find(sh.parked.begin(), sh.parked.end(), true) != sh.parked.end()) {
    c = base;
    c.parks_free = true;
    add("parks", "at the spinning hand-offs' latency", c);
  }
  c = base;
  c.runtime_free = true;
  add("runtime", "free", c);
  c = base;
  c.inflation_free = true;
  add("inflation", "free", c);
  c = base;
  c.interruption_free = true;
  add("interruption", "free", c);
  const std::int64_t host = v.info->host_ns;
  if (s.serial_ns > host) {
    c = base;
    c.serial = host;
    add("serial", "free", c);
  }
  if (v.info->partition_ns > 0) {
    c = base;
    c.serial = s.serial_ns - v.info->partition_ns;
    add("partition", "free", c);
  }
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
      c = base;
      c.balance_thread = heavy;
      c.balance_scale = mean / static_cast<double>(load[heavy]);
      add("imbalance", "thread " + std::to_string(heavy) + " at the mean load", c);
    }
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const WhatIf& a, const WhatIf& b) { return a.gain > b.gain; });
  return out;
}

}  // namespace tgraph::explain::detail
