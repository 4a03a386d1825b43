// SPDX-License-Identifier: MIT
#include "tgraph/partition/simulator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <tuple>
#include <vector>

#include "tgraph/graph/error.hpp"
#include "schedule_program.hpp"

namespace tgraph::partition {

namespace {

using detail::Dep;
using detail::Item;
constexpr std::uint64_t kUnknown = detail::kNoInstance;

void check_assignment(const StepGraph& g, const Assignment& a) {
  if (std::string why = validate(g, a, a.k); !why.empty()) throw Error(why);
}

class Simulator {
 public:
  Simulator(const StepGraph& g, const Assignment& a, const CostModel& m)
      : g_(g), a_(a), k_(a.k), latency_(static_cast<std::uint64_t>(std::llround(m.sync_latency_ns))),
        per_byte_(m.per_byte_ns),
        overhead_(static_cast<std::uint64_t>(std::llround(m.task_overhead_ns))) {
    s_.first_instance = detail::first_instances(g);
    const std::uint64_t total = s_.first_instance.back();
    s_.start_ns.assign(total, 0);
    s_.end_ns.assign(total, kUnknown);
    deps_ = detail::dependencies(g);
    find_fan_ins();
    items_ = detail::programs(g, a);
    state_.resize(k_);
    // The step's serial host work (StepGraph::host_ns) runs before any of its tasks.
    for (State& st : state_) st.time = g_.host_ns;
    s_.busy_ns.assign(k_, 0);
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
  };

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
        for (e = b; e < deps.size() && deps[e].datum == deps[b].datum; ++e) {}
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
        key.push_back((static_cast<std::uint64_t>(deps[j].from) << 2) |
                      (deps[j].raw ? 2u : 0u) | (deps[j].carried ? 1u : 0u));
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
    for (std::size_t j = known ? fi.size : 0; j < deps.size(); ++j) {
      const Dep& d = deps[j];
      const std::uint64_t src = source(d, t, i);
      if (src == kUnknown) continue;
      std::uint64_t arrival = s_.end_ns[src];
      if (a_.proc[d.from] != p) {
        arrival += latency_;
        if (receive(src, d.datum, a_.proc[d.from], p) && d.raw) bytes += g_.data[d.datum].bytes;
      }
      ready = std::max(ready, arrival);
      if (j < fi.size) group = std::max(group, arrival);
    }
    if (known) {
      ready = std::max(ready, memo->arrival);
    } else if (memo != nullptr) {
      *memo = Memo{i, group};
    }
    const std::uint64_t duration =
        g_.tasks[t].cost_ns + overhead_ +
        static_cast<std::uint64_t>(std::llround(static_cast<double>(bytes) * per_byte_));
    const std::uint64_t inst = s_.first_instance[t] + i;
    s_.start_ns[inst] = ready;
    s_.end_ns[inst] = ready + duration;
    st.time = ready + duration;
    s_.busy_ns[p] += duration;
    s_.transfer_bytes += bytes;
    return true;
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
        known += latency_;
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
  const std::uint64_t overhead_;  // CostModel::task_overhead_ns, per instance
  Schedule s_;
  std::vector<std::vector<Dep>> deps_;
  std::vector<FanIn> fan_in_;
  std::vector<Memo> memo_;  // by processor, then fan-in id
  std::size_t fan_ins_ = 0;
  std::vector<std::vector<Item>> items_;
  std::vector<State> state_;
  detail::VersionSet waits_, signals_;
};

}  // namespace

Schedule simulate(const StepGraph& g, const Assignment& a, const CostModel& model) {
  check_assignment(g, a);
  return Simulator(g, a, model).run();
}

std::vector<std::uint64_t> predicted_makespans(const Trace& trace, const TraceAssignment& a,
                                               const CostModel& model) {
  std::vector<std::uint64_t> out;
  for (std::size_t s = 0; s < trace.steps.size() && s < a.steps.size(); ++s)
    out.push_back(simulate(trace.steps[s], a.steps[s], model).makespan_ns);
  return out;
}

}  // namespace tgraph::partition
