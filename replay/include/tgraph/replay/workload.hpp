// SPDX-License-Identifier: MIT
// What an executor runs: the body of each task and the break condition of each loop.
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <vector>

#include "tgraph/graph/step_graph.hpp"

namespace tgraph {
struct ExecGraph;  // tgraph/graph/lowering.hpp
}  // namespace tgraph

namespace tgraph::replay {

/// One execution of one task, as handed to Workload::run.
struct TaskRun {
  const ExecGraph* exec =
      nullptr;  ///< the graph being executed (lowered: tgraph/graph/lowering.hpp)
  TaskId task = 0;                  ///< task id in exec->graph
  TaskId origin = kNoTask;          ///< task id in the original step, kNoTask for a reducer
  std::uint32_t iteration = 0;      ///< loop iteration (0 outside loops)
  std::uint32_t thread = 0;         ///< executor thread running it
};

/// Task bodies and loop conditions. run() may be called concurrently for tasks the
/// dataflow graph leaves independent; stop_after() is called once per loop iteration, by
/// the thread that ran the loop's break task, after that task.
class Workload {
 public:
  Workload() : instance_(next_instance()) {}
  Workload(const Workload&) : instance_(next_instance()) {}
  Workload& operator=(const Workload&) { return *this; }
  virtual ~Workload() = default;
  /// Unique number of this object (executors rebind when it changes).
  std::uint64_t instance() const { return instance_; }
  /// Called on the executor's calling thread when a new structure (plan) is installed.
  virtual void bind(const ExecGraph& exec) { (void)exec; }
  /// Called on the thread that owns datum `d` (exec id) before the first step of a plan,
  /// for every datum whose storage the workload allocates (first touch).
  virtual void first_touch(DatumId d) { (void)d; }
  /// True when first_touch(d) would allocate or touch something.
  virtual bool needs_touch(DatumId d) const {
    (void)d;
    return false;
  }
  /// By original datum: whether CW writers of it can write a temporary instead (nullptr:
  /// all can). Executors serialise the CW groups of the others.
  virtual const std::vector<bool>* reducible() const { return nullptr; }
  /// Runs one task.
  virtual void run(const TaskRun& r) = 0;
  /// After iteration `iteration` (0-based) of loop `loop`: true = leave the loop.
  virtual bool stop_after(LoopId loop, std::uint32_t iteration) = 0;
  /// The number of iterations loop `loop` will run this step when the workload knows it
  /// before the loop starts (a replay of recorded counts), else nullopt (a live condition).
  /// When known, stop_after must agree with it; executors may then unroll the loop.
  virtual std::optional<std::uint32_t> known_iterations(LoopId loop) const {
    (void)loop;
    return std::nullopt;
  }

 private:
  static std::uint64_t next_instance() {
    static std::atomic<std::uint64_t> counter{0};
    // relaxed: only uniqueness matters, which the atomic increment gives.
    return counter.fetch_add(1, std::memory_order_relaxed) + 1;
  }
  std::uint64_t instance_;
};

}  // namespace tgraph::replay
