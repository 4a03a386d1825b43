// SPDX-License-Identifier: MIT
#include "tgraph/model/simulator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <tuple>
#include <vector>

#include "schedule_program.hpp"
#include "tgraph/graph/error.hpp"

namespace tgraph::model {

namespace {

using detail::Dep;
using detail::Item;
constexpr std::uint64_t kUnknown = detail::kNoInstance;

void check_assignment(const StepGraph& g, const Assignment& a) {
  if (std::string why = validate(g, a, a.k); !why.empty()) throw Error(why);
}

std::uint64_t to_ns(double ns) {
  return static_cast<std::uint64_t>(std::llround(std::max(0.0, ns)));
}

class Simulator {
 public:
  // `inflation`: per instance, the factor its cost is scaled by (nullptr: 1).
  Simulator(const StepGraph& g, const Assignment& a, const CostModel& m, std::uint64_t serial_ns,
            const std::vector<double>* inflation)
      : g_(g),
        a_(a),
        k_(a.k),
        latency_(to_ns(m.sync_latency_ns)),
        per_byte_(m.per_byte_ns),
        overhead_(to_ns(m.task_overhead_ns + m.executor_overhead_at(a.k))),
        wake_(to_ns(m.park_wake_ns)),
        budget_(to_ns(m.spin_budget_ns)),
        inflation_(inflation) {
    s_.first_instance = detail::first_instances(g);
    const std::uint64_t total = s_.first_instance.back();
    s_.start_ns.assign(total, 0);
    s_.end_ns.assign(total, kUnknown);
    deps_ = detail::dependencies(g);
    find_fan_ins();
    items_ = detail::programs(g, a);
    state_.resize(k_);
    // The step's serial work (the main thread's, or StepGraph::host_ns) runs before any of
    // its tasks on processor 0, the calling thread; the others wait for it, and when that
    // is longer than they spin they have parked and start a wake-up later.
    for (ProcId p = 0; p < k_; ++p)
      state_[p].time = serial_ns + (p != 0 && wake_ > 0 && serial_ns > budget_ ? wake_ : 0);
    // Each processor's interruptions, seeded by the processor and the step's size.
    pauses_.resize(k_);
    for (ProcId p = 0; p < k_; ++p) {
      const ThreadInterruptions* of = m.interruptions_at(k_, p);
      if (of == nullptr) continue;
      double mean = 0;
      for (double l : of->lengths_ns) mean += l;
      mean /= static_cast<double>(of->lengths_ns.size());
      if (mean < 1.0) continue;
      Pauses& ps = pauses_[p];
      ps.of = of;
      ps.mean_gap = mean * (1.0 - of->lost) / of->lost;
      ps.rng = 0x9e3779b97f4a7c15ull * (p + 1) ^ (total << 17);
      next_gap(ps);
    }
    s_.busy_ns.assign(k_, 0);
    s_.body_ns.assign(k_, 0);
    s_.kind_body_ns.assign(g.kinds.size(), 0);
    s_.finish_ns.assign(k_, 0);
    s_.waits_between.assign(static_cast<std::size_t>(k_) * k_, 0);
  }

  Schedule run() {
    bool progress = true;
    while (progress) {
      progress = false;
      for (ProcId p = 0; p < k_; ++p) progress = advance(p) || progress;
    }
    for (ProcId p = 0; p < k_; ++p)
      if (state_[p].item < items_[p].size()) {
        throw Error(detail::deadlock_message(g_, items_[p][state_[p].item], state_[p].pos, p));
      }
    for (ProcId p = 0; p < k_; ++p) {
      s_.finish_ns[p] = state_[p].time;
      s_.makespan_ns = std::max(s_.makespan_ns, state_[p].time);
    }
    return std::move(s_);
  }

 private:
  struct State {
    std::size_t item = 0;
    std::uint32_t iter = 0;
    std::size_t pos = 0;
    std::uint64_t time = 0;
    std::size_t ready = 0;  // dependencies of the instance tried last known to be done
  };

  // Instance that dependency `d` of iteration `i` of a task refers to; kUnknown for none.
  std::uint64_t source(const Dep& d, TaskId t, std::uint32_t i) const {
    return detail::dependency_source(g_, s_.first_instance, d, t, i);
  }

  // Records that processor p receives (instance, datum) from processor `from`; returns
  // true the first time (a wait, and a signal if nobody received it before).
  bool receive(std::uint64_t instance, DatumId datum, ProcId from, ProcId p) {
    if (!waits_.insert({instance, datum, p})) return false;
    ++s_.waits;
    ++s_.waits_between[static_cast<std::size_t>(from) * k_ + p];
    if (signals_.insert({instance, datum, 0})) ++s_.signals;
    return true;
  }

  // A task's largest group of at least kFanIn dependencies on one datum (the CW writers of
  // a CG scalar that every object's task reads) goes first in its list; readers with the
  // same group (same datum, loop and sources) share one id, so that after the first of
  // them on a processor the others reuse its arrival time: their receives are all repeats
  // (no wait, no signal, no bytes), and the scan is quadratic in the group otherwise.
  static constexpr std::size_t kFanIn = 8;
  static constexpr std::uint32_t kNoFanIn = UINT32_MAX;
  struct FanIn {
    std::uint32_t id = kNoFanIn;
    std::uint32_t size = 0;  // deps_[t][0, size) are the group
  };
  struct Memo {
    std::uint32_t iter = UINT32_MAX;  // the instance (iteration) whose arrival is kept
    std::uint64_t arrival = 0;
    std::uint64_t remote_end = 0;  // the latest end of the group's remote sources
  };

  // When a processor free at `free` can go on, given that its dependencies allow `ready`
  // and the last of them sent from another processor ended at `remote_end`: a wait that
  // outlasts the spin budget has parked, and the hand-off that ends it is a wake-up.
  std::uint64_t woken(std::uint64_t free, std::uint64_t ready, std::uint64_t remote_end) const {
    if (wake_ == 0 || ready <= free || ready - free <= budget_ || remote_end + latency_ < ready)
      return ready;
    return std::max(ready, remote_end + wake_);
  }

  void find_fan_ins() {
    fan_in_.assign(deps_.size(), FanIn{});
    std::map<std::vector<std::uint64_t>, std::uint32_t> ids;
    std::vector<std::uint64_t> key;
    for (TaskId t = 0; t < deps_.size(); ++t) {
      std::vector<Dep>& deps = deps_[t];
      if (deps.size() < kFanIn) continue;
      std::sort(deps.begin(), deps.end(), [](const Dep& x, const Dep& y) {
        return std::tie(x.datum, x.from, x.carried, x.raw) <
               std::tie(y.datum, y.from, y.carried, y.raw);
      });
      std::size_t best = 0, best_len = 0;
      for (std::size_t b = 0, e = 0; b < deps.size(); b = e) {
        for (e = b; e < deps.size() && deps[e].datum == deps[b].datum; ++e) {
        }
        if (e - b > best_len) {
          best = b;
          best_len = e - b;
        }
      }
      if (best_len < kFanIn) continue;
      std::rotate(deps.begin(), deps.begin() + static_cast<std::ptrdiff_t>(best),
                  deps.begin() + static_cast<std::ptrdiff_t>(best + best_len));
      key.assign({deps[0].datum, g_.tasks[t].loop});
      for (std::size_t j = 0; j < best_len; ++j)
        key.push_back((static_cast<std::uint64_t>(deps[j].from) << 2) | (deps[j].raw ? 2u : 0u) |
                      (deps[j].carried ? 1u : 0u));
      const auto [it, fresh] = ids.emplace(key, static_cast<std::uint32_t>(ids.size()));
      fan_in_[t] = {it->second, static_cast<std::uint32_t>(best_len)};
    }
    memo_.assign(static_cast<std::size_t>(k_) * ids.size(), Memo{});
    fan_ins_ = ids.size();
  }

  bool try_run(ProcId p, TaskId t, std::uint32_t i) {
    State& st = state_[p];
    const std::vector<Dep>& deps = deps_[t];
    const FanIn fi = fan_in_[t];
    Memo* memo = fi.id == kNoFanIn ? nullptr : &memo_[p * fan_ins_ + fi.id];
    const bool known = memo != nullptr && memo->iter == i;
    // The dependencies before st.ready finished when this instance was last tried: a
    // processor polled while it waits rescans only the rest.
    if (known) st.ready = std::max<std::size_t>(st.ready, fi.size);
    for (; st.ready < deps.size(); ++st.ready) {
      const std::uint64_t src = source(deps[st.ready], t, i);
      if (src != kUnknown && s_.end_ns[src] == kUnknown) return false;
    }
    st.ready = 0;
    std::uint64_t ready = st.time, bytes = 0, group = 0;
    std::uint64_t remote_end = 0, group_remote_end = 0;  // latest ends of remote sources
    for (std::size_t j = known ? fi.size : 0; j < deps.size(); ++j) {
      const Dep& d = deps[j];
      const std::uint64_t src = source(d, t, i);
      if (src == kUnknown) continue;
      std::uint64_t arrival = s_.end_ns[src];
      if (a_.proc[d.from] != p) {
        remote_end = std::max(remote_end, arrival);
        if (j < fi.size) group_remote_end = std::max(group_remote_end, arrival);
        arrival += latency_;
        if (receive(src, d.datum, a_.proc[d.from], p) && d.raw) bytes += g_.data[d.datum].bytes;
      }
      ready = std::max(ready, arrival);
      if (j < fi.size) group = std::max(group, arrival);
    }
    if (known) {
      ready = std::max(ready, memo->arrival);
      remote_end = std::max(remote_end, memo->remote_end);
    } else if (memo != nullptr) {
      *memo = Memo{i, group, group_remote_end};
    }
    ready = woken(st.time, ready, remote_end);
    std::uint64_t start = ready;
    const std::uint64_t inst = s_.first_instance[t] + i;
    const double cost = static_cast<double>(g_.tasks[t].cost_ns) *
                        (inflation_ != nullptr ? (*inflation_)[inst] : 1.0);
    const std::uint64_t duration =
        to_ns(cost) + overhead_ +
        static_cast<std::uint64_t>(std::llround(static_cast<double>(bytes) * per_byte_));
    std::uint64_t end = start + duration;
    if (pauses_[p].of != nullptr) std::tie(start, end) = interrupted(pauses_[p], ready, duration);
    s_.start_ns[inst] = start;
    s_.end_ns[inst] = end;
    st.time = end;
    s_.busy_ns[p] += end - start;
    // The body's time as a live run's clock sees it: its cost and the gaps inside it.
    s_.body_ns[p] += to_ns(cost) + (end - start - duration);
    if (g_.tasks[t].kind < s_.kind_body_ns.size()) s_.kind_body_ns[g_.tasks[t].kind] += to_ns(cost);
    s_.transfer_bytes += bytes;
    return true;
  }

  // A processor's interruptions, in time order: the next gap is [start, end).
  struct Pauses {
    const ThreadInterruptions* of = nullptr;  // nullptr: none
    double mean_gap = 0;                      // mean time from one gap's end to the next's start
    std::uint64_t rng = 0;
    std::uint64_t start = 0, end = 0;
  };

  static std::uint64_t next_random(std::uint64_t& state) {  // splitmix64
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }

  // Draws the gap after the current one: exponentially spaced (mean_gap), its length one of
  // the measured ones at random; the processor loses `lost` of its time on average.
  static void next_gap(Pauses& ps) {
    const double u = static_cast<double>(next_random(ps.rng) >> 11) * 0x1.0p-53;  // [0, 1)
    const double spacing = -std::log1p(-u) * ps.mean_gap;
    const std::vector<double>& lengths = ps.of->lengths_ns;
    const double length = lengths[next_random(ps.rng) % lengths.size()];
    ps.start = ps.end + std::max<std::uint64_t>(1, to_ns(spacing));
    ps.end = ps.start + to_ns(length);
  }

  // [start, end) of a body of `duration` ns ready at `ready` on a processor interrupted by
  // `ps`: gaps over before it is ready cost nothing (the processor was waiting); one under
  // way delays its start; those that begin while it runs lengthen it.
  static std::pair<std::uint64_t, std::uint64_t> interrupted(Pauses& ps, std::uint64_t ready,
                                                             std::uint64_t duration) {
    while (ps.end <= ready) next_gap(ps);
    std::uint64_t start = ready;
    if (ps.start <= start) {
      start = ps.end;
      next_gap(ps);
    }
    std::uint64_t t = start, left = duration;
    while (ps.start < t + left) {
      left -= ps.start - t;
      t = ps.end;
      next_gap(ps);
    }
    return {start, t + left};
  }

  // Runs processor p as far as it can; returns whether it moved.
  bool advance(ProcId p) {
    State& st = state_[p];
    bool moved = false;
    while (st.item < items_[p].size()) {
      const Item& it = items_[p][st.item];
      if (it.task != kNoTask) {
        if (!try_run(p, it.task, 0)) return moved;
        ++st.item;
        moved = true;
        continue;
      }
      const Loop& loop = g_.loops[it.loop];
      if (loop.iterations == 0) {
        ++st.item;
        moved = true;
        continue;
      }
      if (st.pos < it.body.size()) {
        if (!try_run(p, it.body[st.pos], st.iter)) return moved;
        ++st.pos;
        moved = true;
        continue;
      }
      // End of iteration: loop control needs the break task's decision.
      const TaskId brk = loop.last - 1;
      const std::uint64_t inst = s_.first_instance[brk] + st.iter;
      if (s_.end_ns[inst] == kUnknown) return moved;
      std::uint64_t known = s_.end_ns[inst];
      if (a_.proc[brk] != p) {
        known = woken(st.time, known + latency_, known);
        receive(inst, loop.condition, a_.proc[brk], p);
      }
      st.time = std::max(st.time, known);
      st.pos = 0;
      if (++st.iter == loop.iterations) {
        st.iter = 0;
        ++st.item;
      }
      moved = true;
    }
    return moved;
  }

  const StepGraph& g_;
  const Assignment& a_;
  const std::uint32_t k_;
  const std::uint64_t latency_;
  const double per_byte_;
  // CostModel::task_overhead_ns and the executor's time at a.k processors, per instance
  const std::uint64_t overhead_;
  const std::uint64_t wake_;              // CostModel::park_wake_ns (0: term off)
  const std::uint64_t budget_;            // CostModel::spin_budget_ns
  const std::vector<double>* inflation_;  // per instance, or nullptr
  Schedule s_;
  std::vector<std::vector<Dep>> deps_;
  std::vector<FanIn> fan_in_;
  std::vector<Memo> memo_;  // by processor, then fan-in id
  std::size_t fan_ins_ = 0;
  std::vector<std::vector<Item>> items_;
  std::vector<State> state_;
  detail::VersionSet waits_, signals_;
  std::vector<Pauses> pauses_;  // by processor
};

// Per instance of `s`, the time-weighted mean number of instances running at once during
// it (itself included), from the instances' intervals.
std::vector<double> mean_busy(const Schedule& s) {
  const std::size_t n = s.start_ns.size();
  std::vector<std::pair<std::uint64_t, int>> events;
  events.reserve(2 * n);
  for (std::size_t i = 0; i < n; ++i)
    if (s.end_ns[i] > s.start_ns[i]) {
      events.push_back({s.start_ns[i], +1});
      events.push_back({s.end_ns[i], -1});
    }
  std::sort(events.begin(), events.end());
  // times[j]: the j-th distinct event time; area[j]: the integral of the count up to it;
  // count[j]: the count just after it.
  std::vector<std::uint64_t> times;
  std::vector<double> area;
  std::vector<int> count;
  int c = 0;
  double a = 0;
  for (std::size_t e = 0; e < events.size();) {
    const std::uint64_t t = events[e].first;
    if (!times.empty())
      a += static_cast<double>(count.back()) * static_cast<double>(t - times.back());
    for (; e < events.size() && events[e].first == t; ++e) c += events[e].second;
    times.push_back(t);
    area.push_back(a);
    count.push_back(c);
  }
  auto area_at = [&](std::uint64_t t) {  // t is an event time
    const auto j =
        static_cast<std::size_t>(std::lower_bound(times.begin(), times.end(), t) - times.begin());
    return area[j];
  };
  std::vector<double> busy(n, 1.0);
  for (std::size_t i = 0; i < n; ++i)
    if (s.end_ns[i] > s.start_ns[i])
      busy[i] = (area_at(s.end_ns[i]) - area_at(s.start_ns[i])) /
                static_cast<double>(s.end_ns[i] - s.start_ns[i]);
  return busy;
}

}  // namespace

Schedule simulate(const StepGraph& g, const Assignment& a, const CostModel& model,
                  std::optional<std::uint64_t> serial_ns) {
  check_assignment(g, a);
  const std::uint64_t serial = serial_ns.value_or(g.host_ns);
  Schedule s = Simulator(g, a, model, serial, nullptr).run();
  if ((model.inflation.empty() && model.compute_inflation.empty()) || a.k < 2) return s;
  // The bodies' slow-down: each instance's cost scaled by the inflation at the number of
  // instances that ran at once during it in the schedule without inflation (its memory
  // share, the bytes of the data it accesses, by the memory body's curve; the rest by the
  // compute body's).
  std::vector<double> factor = mean_busy(s);
  for (TaskId t = 0; t < g.tasks.size(); ++t) {
    double bytes = 0;
    for (const Access& acc : g.accesses_of(t))
      bytes += static_cast<double>(g.data[acc.datum].bytes);
    const auto cost = static_cast<double>(g.tasks[t].cost_ns);
    for (std::uint64_t i = s.first_instance[t]; i < s.first_instance[t + 1]; ++i)
      factor[i] = model.task_inflation(factor[i], cost, bytes);
  }
  return Simulator(g, a, model, serial, &factor).run();
}

std::vector<std::uint64_t> predicted_makespans(const Trace& trace, const TraceAssignment& a,
                                               const CostModel& model,
                                               const std::vector<std::uint64_t>* serial_ns) {
  std::vector<std::uint64_t> out;
  for (std::size_t s = 0; s < trace.steps.size() && s < a.steps.size(); ++s) {
    std::optional<std::uint64_t> serial;
    if (serial_ns != nullptr && s < serial_ns->size()) serial = (*serial_ns)[s];
    out.push_back(simulate(trace.steps[s], a.steps[s], model, serial).makespan_ns);
  }
  return out;
}

std::vector<std::string> model_terms(const CostModel& model, bool serial_given, bool host_time) {
  std::vector<std::string> terms = {"sync_latency", "per_byte"};
  if (model.source == "ideal") terms.clear();
  if (model.task_overhead_ns > 0) terms.push_back("task_overhead");
  if (!model.executor_overhead.empty()) terms.push_back("executor_overhead");
  if (model.park_wake_ns > 0) terms.push_back("park_wake");
  if (!model.interruptions.empty()) terms.push_back("interruptions");
  if (!model.inflation.empty()) terms.push_back("inflation");
  // The compute body's curve, and the memory share that splits a task between the two.
  if (!model.compute_inflation.empty()) terms.push_back("compute_inflation");
  if (model.inflation_ns_per_byte > 0 && !model.inflation.empty()) terms.push_back("memory_share");
  if (serial_given) {
    terms.push_back("serial_main_thread");
  } else if (host_time) {
    terms.push_back("host_time");
  }
  return terms;
}

}  // namespace tgraph::model
