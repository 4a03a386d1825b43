// SPDX-License-Identifier: MIT
// Internal: the observers of a live run (cost feedback for the partitioner, time per kind).
#pragma once

#include <algorithm>
#include <cstdint>
#include <map>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "tgraph/graph/lowering.hpp"
#include "tgraph/graph/step_graph.hpp"
#include "tgraph/replay/observer.hpp"

namespace tgraph::measure::detail {

/// A task's cost after a new measurement `sample`: an exponential average with the cost
/// `old` already there (half weight to the new sample; `old` <= 1 means none yet), so that one
/// preempted step does not look like an imbalance.
inline std::uint64_t smoothed_cost(std::uint64_t old, std::uint64_t sample) {
  return std::max<std::uint64_t>(1, old > 1 ? (old + sample) / 2 : sample);
}

/// Mean measured duration of each exec task in the last step (sampled iterations), for the
/// next step's partitioning: deferred recording measures nothing itself.
class CostObserver : public replay::Observer {
 public:
  void on_step_begin(const ExecGraph& exec, std::uint32_t threads, std::int64_t) override {
    exec_ = &exec;
    begin_.assign(static_cast<std::size_t>(threads) * 8, 0);
    sum_.assign(exec.graph.tasks.size(), 0);
    max_.assign(exec.graph.tasks.size(), 0);
    runs_.assign(exec.graph.tasks.size(), 0);
  }
  void on_begin(std::uint32_t thread, TaskId, std::uint32_t, std::int64_t t) override {
    begin_[thread * 8] = t;
  }
  void on_end(std::uint32_t thread, TaskId task, std::uint32_t, std::int64_t t) override {
    // One writer per task at a time: instances of a task never overlap, and the executors
    // order consecutive instances (dependency or same thread).
    const auto d = static_cast<std::uint64_t>(t - begin_[thread * 8]);
    sum_[task] += d;
    max_[task] = std::max(max_[task], d);
    ++runs_[task];
  }
  /// Writes the measured means into `g` (the next step): by task index when `g` has the
  /// structure of the measured step, else by stable key; tasks never measured get 1 ns.
  /// `match` (optional): partition::match_by_key(g, measured), when the caller has it.
  void apply(const StepGraph& measured, StepGraph& g,
             const std::vector<TaskId>* match = nullptr) const {
    if (exec_ == nullptr) {
      for (Task& t : g.tasks) t.cost_ns = 1;
      return;
    }
    if (&measured == &g ||
        (g.tasks.size() == measured.tasks.size() && g.same_structure(measured))) {
      // Same tasks: smoothed over steps.
      for (TaskId t = 0; t < sum_.size(); ++t) {
        const TaskId o = exec_->origin[t];
        if (o == kNoTask || o >= g.tasks.size() || runs_[t] == 0) continue;
        g.tasks[o].cost_ns = smoothed_cost(measured.tasks[o].cost_ns, mean(t));
      }
      return;
    }
    std::vector<std::uint64_t> cost(measured.tasks.size(), 0);
    for (TaskId t = 0; t < sum_.size(); ++t) {
      const TaskId o = exec_->origin[t];
      if (o != kNoTask && o < cost.size() && runs_[t] > 0) cost[o] = mean(t);
    }
    if (match != nullptr && match->size() == g.tasks.size()) {
      for (TaskId t = 0; t < g.tasks.size(); ++t) {
        const TaskId m = (*match)[t];
        g.tasks[t].cost_ns = m != kNoTask && m < cost.size() ? std::max<std::uint64_t>(1, cost[m]) : 1;
      }
      return;
    }
    std::unordered_map<StableKey, std::uint64_t> by_key;
    by_key.reserve(cost.size());
    for (TaskId t = 0; t < cost.size(); ++t) by_key[measured.tasks[t].key] = cost[t];
    for (Task& t : g.tasks) {
      const auto it = by_key.find(t.key);
      t.cost_ns = it != by_key.end() ? std::max<std::uint64_t>(1, it->second) : 1;
    }
  }

 private:
  // The mean of task t's samples in the step, its longest left out from three samples on: a
  // loop task's instance preempted by the host (a 4 ms time slice in a 10 us body) would
  // otherwise look like a task 60 times heavier and draw a rebalance.
  std::uint64_t mean(TaskId t) const {
    return runs_[t] >= 3 ? (sum_[t] - max_[t]) / (runs_[t] - 1) : sum_[t] / runs_[t];
  }

  const ExecGraph* exec_ = nullptr;
  std::vector<std::int64_t> begin_;
  std::vector<std::uint64_t> sum_, max_, runs_;
};

/// Time per task kind over the whole run.
class KindObserver : public replay::Observer {
 public:
  void on_step_begin(const ExecGraph& exec, std::uint32_t threads, std::int64_t) override {
    exec_ = &exec;
    slots_.resize(threads);
    for (Slot& s : slots_) s.sum.assign(exec.graph.kinds.size(), {0, 0});
  }
  void on_begin(std::uint32_t thread, TaskId, std::uint32_t, std::int64_t t) override {
    slots_[thread].begin = t;
  }
  void on_end(std::uint32_t thread, TaskId task, std::uint32_t, std::int64_t t) override {
    Slot& s = slots_[thread];
    auto& k = s.sum[exec_->graph.tasks[task].kind];
    k.first += t - s.begin;
    ++k.second;
  }
  void on_step_end(std::int64_t) override {
    for (const Slot& s : slots_)
      for (KindId k = 0; k < s.sum.size(); ++k) {
        auto& tot = total_[exec_->graph.kinds[k]];
        tot.first += s.sum[k].first;
        tot.second += s.sum[k].second;
      }
  }
  const std::map<std::string, std::pair<std::int64_t, std::uint64_t>>& total() const {
    return total_;
  }

 private:
  struct alignas(64) Slot {
    std::int64_t begin = 0;
    std::vector<std::pair<std::int64_t, std::uint64_t>> sum;  // by kind: ns, instances
  };
  const ExecGraph* exec_ = nullptr;
  std::vector<Slot> slots_;
  std::map<std::string, std::pair<std::int64_t, std::uint64_t>> total_;
};

}  // namespace tgraph::measure::detail
