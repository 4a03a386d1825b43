// SPDX-License-Identifier: MIT
// The attribution of a step's lost time and its executed critical path (docs/explain.md).
#include "tgraph/explain/explain.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <tuple>

#include "step_view.hpp"
#include "tgraph/graph/error.hpp"
#include "what_if.hpp"

namespace tgraph::explain {

using detail::Instance;
using detail::kNone;
using detail::StepView;

std::int64_t Causes::sum() const {
  return serial + imbalance + dependency_wait + handoff + interruption + inflation + runtime +
         starvation + residual;
}

Causes& Causes::operator+=(const Causes& o) {
  for (const std::string_view n : cause_names()) cause(*this, n) += cause(o, n);
  return *this;
}

Attribution& Attribution::operator+=(const Attribution& o) {
  lost_ns += o.lost_ns;
  causes += o.causes;
  return *this;
}

const std::vector<std::string_view>& cause_names() {
  static const std::vector<std::string_view> names = {
      "serial",       "imbalance", "dependency_wait", "handoff",  "interruption",
      "inflation",    "runtime",   "starvation",      "residual"};
  return names;
}

std::int64_t& cause(Causes& c, std::string_view name) {
  if (name == "serial") return c.serial;
  if (name == "imbalance") return c.imbalance;
  if (name == "dependency_wait") return c.dependency_wait;
  if (name == "handoff") return c.handoff;
  if (name == "interruption") return c.interruption;
  if (name == "inflation") return c.inflation;
  if (name == "runtime") return c.runtime;
  if (name == "starvation") return c.starvation;
  return c.residual;
}

std::int64_t cause(const Causes& c, std::string_view name) {
  return cause(const_cast<Causes&>(c), name);
}

std::string_view to_string(Link link) {
  switch (link) {
    case Link::kBody:
      return "body";
    case Link::kWait:
      return "wait";
    case Link::kHandoff:
      return "handoff";
    case Link::kSerial:
      return "serial";
  }
  return "body";
}

namespace {

// Time of [a, b] covered by one thread's waits (sorted by start); `from` moves past the
// waits that end before a (segments come in order).
std::int64_t covered_by_waits(const std::vector<const detail::Wait*>& waits, std::size_t& from,
                              std::int64_t a, std::int64_t b) {
  std::int64_t covered = 0, cursor = a;
  while (from < waits.size() && waits[from]->end <= a) ++from;
  for (std::size_t k = from; k < waits.size(); ++k) {
    const detail::Wait& w = *waits[k];
    if (w.end <= cursor) continue;
    if (w.start >= b) break;
    const std::int64_t lo = std::max(cursor, w.start), hi = std::min(b, w.end);
    if (hi > lo) {
      covered += hi - lo;
      cursor = hi;
    }
  }
  return covered;
}

struct LateKey {
  std::uint32_t instance_task;
  DatumId datum;
  bool operator<(const LateKey& o) const {
    return instance_task != o.instance_task ? instance_task < o.instance_task : datum < o.datum;
  }
};

// Walks the executed chain that ends with instance `x` backwards, as the critical path
// does: the body, then what released it (its latest predecessor on another thread when that
// ended after its thread was free: a hand-off, else its thread's previous body, with the
// runtime's wait between them, else the step's start). Calls seg(link, instance, start,
// end) for each piece, later pieces first, each ending where the next one (in time) starts;
// stops once a piece starts at or before `lo`.
template <typename Seg>
void walk_back(const StepView& v, std::uint32_t x, std::int64_t lo, Seg seg) {
  std::int64_t cursor = v.instances[x].end;
  const auto piece = [&](Link link, std::uint32_t k, std::int64_t start, std::int64_t end) {
    end = std::min(end, cursor);
    start = std::min(start, end);
    seg(link, k, start, end);
    cursor = start;
    return start > lo;
  };
  for (std::size_t guard = 0; guard <= v.instances.size(); ++guard) {
    const Instance& i = v.instances[x];
    if (!piece(Link::kBody, x, i.start, i.end)) return;
    const std::int64_t thread_free = i.prev == kNone ? 0 : v.instances[i.prev].end;
    if (i.latest != kNone && v.instances[i.latest].thread != i.thread && i.ready >= thread_free) {
      if (!piece(Link::kHandoff, x, i.ready, cursor)) return;
      x = i.latest;
    } else if (i.prev != kNone) {
      if (!piece(Link::kWait, x, thread_free, cursor)) return;
      x = i.prev;
    } else {
      piece(Link::kWait, x, 0, cursor);
      return;
    }
  }
  if (cursor > lo) seg(Link::kWait, kNone, lo, cursor);  // a cycle guard cut the chain
}

// Idle time of a thread, [lo, hi], spent waiting on the chain that ends with instance `x`
// (hi: its end): each piece of that chain it overlaps lends it its cause (a body's cost is
// work others could not do in parallel: `work`; its inflation and interruption theirs; a
// hand-off's latency: handoff; the runtime's gaps: runtime), after Scalasca's delay
// propagation (Böhme et al.).
void blame(const StepView& v, std::uint32_t x, std::int64_t lo, std::int64_t hi, Causes& c,
           std::int64_t& work) {
  if (hi <= lo) return;
  walk_back(v, x, lo, [&](Link link, std::uint32_t k, std::int64_t start, std::int64_t end) {
    const std::int64_t d = std::min(end, hi) - std::max(start, lo);
    if (d <= 0) return;
    if (link == Link::kHandoff) {
      c.handoff += d;
    } else if (link == Link::kWait || k == kNone) {
      c.runtime += d;
    } else {
      const Instance& i = v.instances[k];
      const std::int64_t len = i.end - i.start;
      if (i.reducer || len <= 0) {
        c.runtime += d;
        return;
      }
      // The overlap split as the body splits: cost, then interruption, then inflation.
      const double share = static_cast<double>(d) / static_cast<double>(len);
      const std::int64_t off = std::llround(share * static_cast<double>(i.interrupted()));
      const std::int64_t base =
          std::min<std::int64_t>(d - off, std::llround(share * static_cast<double>(std::min(i.cost, len))));
      work += base;
      c.interruption += off;
      c.inflation += d - off - base;
    }
  });
}

StepExplanation explain_step(const Timeline& t, const TimelineStep& info,
                             const ExplainOptions& options) {
  const StepView v = detail::make_view(t, info);
  const TimelineGraph& g = *v.graph;
  const std::int64_t K = v.threads;
  StepExplanation s;
  s.step = info.step;
  s.threads = v.threads;
  s.serial_ns = info.serial_ns();
  s.makespan_ns = s.serial_ns + v.wall;
  s.span_ns = v.span;
  s.instances = v.instances.size();
  s.unobserved = v.unobserved;

  // Sequential work and each thread's share of it.
  std::int64_t work = 0;
  std::vector<std::int64_t> load(v.threads, 0);
  for (const Instance& i : v.instances) {
    if (i.reducer) continue;
    work += i.cost;
    load[i.thread] += i.cost;
  }
  s.work_ns = work + info.host_ns;
  Attribution& a = s.attribution;
  a.lost_ns = K * s.makespan_ns - s.work_ns;
  Causes& c = a.causes;
  c.serial = K * s.serial_ns - info.host_ns;

  // Bodies: beyond their sequential cost, the OS's share (wall - CPU) and the rest.
  for (const Instance& i : v.instances) {
    const std::int64_t d = i.end - i.start;
    if (i.reducer) {
      c.runtime += d;
      continue;
    }
    const std::int64_t off = i.interrupted();
    c.interruption += off;
    c.inflation += d - off - i.cost;
  }

  // The last instance to end: the step's critical path ends there.
  std::uint32_t last = kNone;
  for (std::uint32_t k = 0; k < v.instances.size(); ++k)
    if (last == kNone || v.instances[k].end >= v.instances[last].end) last = k;
  const std::int64_t last_end = last == kNone ? 0 : v.instances[last].end;

  // The time between bodies, thread by thread. Before a body's inputs were ready the thread
  // idles on the chain that produced them (blame), named by the writer it waited for; after
  // that it hands off (inside a recorded wait) or the runtime has it. After its last body it
  // idles on the step's critical path, then on the join.
  std::int64_t idle_work = 0;
  std::map<LateKey, LateWriter> late;
  std::vector<std::vector<const detail::Wait*>> waits(v.threads);
  for (const detail::Wait& w : v.waits)
    if (w.thread < v.threads) waits[w.thread].push_back(&w);
  for (std::uint32_t th = 0; th < v.threads; ++th) {
    std::int64_t cursor = 0;
    std::size_t from = 0;
    for (const std::uint32_t k : v.by_thread[th]) {
      const Instance& x = v.instances[k];
      const std::int64_t a0 = cursor, b = std::max(cursor, x.start);
      if (b > a0) {
        const std::int64_t ready = x.latest == kNone ? a0 : std::clamp(x.ready, a0, b);
        if (ready > a0) {
          blame(v, x.latest, a0, ready, c, idle_work);
          const Instance& u = v.instances[x.latest];
          LateWriter& w = late[{u.task, x.datum}];
          w.task = u.task;
          w.kind = g.kinds[g.task_kind[u.task]];
          w.datum = x.datum < g.data.size() ? g.data[x.datum] : "(loop decision)";
          w.wait_ns += ready - a0;
          const std::int64_t u_ready = u.latest == kNone ? 0 : u.ready;
          w.late_ns = std::max(w.late_ns, u.start - u_ready);
        }
        const std::int64_t handed = covered_by_waits(waits[th], from, ready, b);
        c.handoff += handed;
        c.runtime += b - ready - handed;
      }
      cursor = std::max(cursor, x.end);
    }
    if (v.wall > cursor) {
      if (last != kNone && last_end > cursor) blame(v, last, cursor, last_end, c, idle_work);
      c.runtime += v.wall - std::max(cursor, last_end);  // the join
    }
  }

  // Idle time over work done elsewhere: the graph's span first (starvation), then the
  // assignment's heaviest thread beyond what K threads allow (imbalance), the rest waiting
  // on writers that came late.
  const std::int64_t heaviest = load.empty() ? 0 : *std::max_element(load.begin(), load.end());
  const std::int64_t k1 = std::max<std::int64_t>(K, 1);
  const std::int64_t ideal = std::max((work + k1 - 1) / k1, v.span);
  c.starvation = std::min(idle_work, K * std::max<std::int64_t>(0, v.span - work / k1));
  c.imbalance = std::min(idle_work - c.starvation, K * std::max<std::int64_t>(0, heaviest - ideal));
  c.dependency_wait = idle_work - c.starvation - c.imbalance;
  // What the timeline does not cover: overlapping events on a thread, events outside the
  // window (0 for a consistent timeline).
  c.residual = a.lost_ns - (c.sum() - c.residual);

  for (auto& [key, w] : late) s.late_writers.push_back(w);
  std::sort(s.late_writers.begin(), s.late_writers.end(),
            [](const LateWriter& x, const LateWriter& y) { return x.wait_ns > y.wait_ns; });
  if (s.late_writers.size() > 5) s.late_writers.resize(5);

  // The executed critical path and the makespan along it.
  std::vector<PathLink> path;
  Causes along;
  std::int64_t along_work = 0;
  const auto link = [&](std::optional<TaskId> task, std::uint32_t thread, std::uint32_t it,
                        std::int64_t start, std::int64_t end, Link kind) {
    PathLink l;
    l.task = task;
    l.kind = task ? g.kinds[g.task_kind[*task]] : std::string();
    l.thread = thread;
    l.iteration = it;
    l.start_ns = start + s.serial_ns;
    l.end_ns = end + s.serial_ns;
    l.link = kind;
    path.push_back(l);
  };
  if (last != kNone) {
    if (v.wall > last_end) {
      link(std::nullopt, 0, 0, last_end, v.wall, Link::kWait);
      along.runtime += v.wall - last_end;
    }
    walk_back(v, last, std::numeric_limits<std::int64_t>::min(),
              [&](Link kind, std::uint32_t k, std::int64_t start, std::int64_t end) {
                if (k == kNone) {
                  link(std::nullopt, 0, 0, start, end, kind);
                  along.runtime += end - start;
                  return;
                }
                const Instance& i = v.instances[k];
                if (kind != Link::kBody && end == start) return;  // no time, nothing to name
                link(i.task, i.thread, i.iteration, start, end, kind);
                if (kind == Link::kHandoff) {
                  along.handoff += end - start;
                } else if (kind == Link::kWait) {
                  along.runtime += end - start;
                } else {
                  std::int64_t w = 0;
                  // The piece of the body on the path (all of it, unless clipped).
                  const std::int64_t d = end - start, len = i.end - i.start;
                  if (i.reducer || len <= 0) {
                    along.runtime += d;
                    return;
                  }
                  const double share = static_cast<double>(d) / static_cast<double>(len);
                  const std::int64_t off = std::llround(share * static_cast<double>(i.interrupted()));
                  w = std::min<std::int64_t>(d - off, std::llround(share * static_cast<double>(std::min(i.cost, len))));
                  along_work += w;
                  along.interruption += off;
                  along.inflation += d - off - w;
                }
              });
  } else {
    along.runtime += v.wall;
  }
  if (s.serial_ns > 0) {
    PathLink l;
    l.start_ns = 0;
    l.end_ns = s.serial_ns;
    l.link = Link::kSerial;
    path.push_back(l);
  }
  std::reverse(path.begin(), path.end());
  s.critical_path = std::move(path);
  s.makespan_split = {{"work", along_work},           {"serial", s.serial_ns},
                      {"inflation", along.inflation}, {"interruption", along.interruption},
                      {"handoff", along.handoff},     {"runtime", along.runtime}};
  if (options.what_ifs) s.what_if = detail::what_ifs(v, s, options.simulator_fit, &s.simulated_ns);
  return s;
}

}  // namespace

Explanation explain_timeline(const Timeline& t, const std::string& name,
                             const ExplainOptions& options) {
  if (t.step_info.empty())
    throw InputError(name, std::nullopt,
                     "the timeline carries no step graphs (written before tgraph recorded "
                     "them; record it again with --timeline)");
  Explanation e;
  e.threads = t.threads;
  // The steps' what-ifs summed, by (scope, target, change), in the order first seen.
  using Key = std::tuple<std::string, std::string, std::string>;
  std::map<Key, WhatIf> total;
  std::vector<Key> order;
  for (const TimelineStep& info : t.step_info) {
    if (options.step && info.step != *options.step) continue;
    e.steps.push_back(explain_step(t, info, options));
    const StepExplanation& s = e.steps.back();
    e.attribution += s.attribution;
    for (const WhatIf& w : s.what_if) {
      const Key key{w.scope, w.target, w.change};
      auto [it, fresh] = total.try_emplace(key, WhatIf{w.target, w.change, 0, 0, w.model, w.scope});
      if (fresh) order.push_back(key);
      if (it->second.model != w.model) it->second.model = "mixed";  // steps on both models
      it->second.predicted_ns += w.predicted_ns;
      it->second.gain += w.gain;
    }
  }
  if (e.steps.empty()) {
    std::string have;
    for (const TimelineStep& info : t.step_info)
      have += (have.empty() ? "" : ", ") + std::to_string(info.step);
    if (have.size() > 60) have = have.substr(0, 60) + "...";
    throw InputError(name, std::nullopt,
                     "no step " + std::to_string(*options.step) + " (steps with graphs: " + have +
                         ")");
  }
  for (const auto& key : order) e.what_if.push_back(total[key]);
  std::stable_sort(e.what_if.begin(), e.what_if.end(),
                   [](const WhatIf& x, const WhatIf& y) { return x.gain > y.gain; });
  return e;
}

void set_kind_costs(Timeline& t,
                    const std::vector<std::pair<std::string, double>>& mean_ns_by_kind) {
  for (TimelineStep& s : t.step_info) {
    const TimelineGraph& g = t.graphs[s.graph];
    std::vector<std::int64_t> by_kind(g.kinds.size(), -1);
    for (KindId k = 0; k < g.kinds.size(); ++k)
      for (const auto& [name, mean] : mean_ns_by_kind)
        if (name == g.kinds[k]) by_kind[k] = std::llround(mean);
    for (TaskId task = 0; task < s.cost_ns.size(); ++task)
      if (g.origin[task] != kNoTask && by_kind[g.task_kind[task]] >= 0)
        s.cost_ns[task] = by_kind[g.task_kind[task]];
  }
}

}  // namespace tgraph::explain
